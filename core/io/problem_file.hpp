// The user's own case in a JSON file (--problem case.json): every key is
// optional, and what is left out is the seed benchmark. // comments are
// allowed. Schema (drivers/cases/README.md, with a commented example):
//
//   "mesh":     {"level": L} or {"dims": [EX, EY, EZ]}
//   "box":      {"lengths": [LX, LY, LZ], "origin": [X0, Y0, Z0]}      [m]
//   "material": {"E": E, "nu": NU}                                     [Pa, -]
//   "loads":    {"traction": {"x1"|"y0"|"y1"|"z1": [TX, TY, TZ], ...},  [Pa]
//                "body_force": [BX, BY, BZ], "scale": S}                [N/m^3, -]
//               (with "traction", the faces not listed carry none; x = x0
//               is clamped and z = z0 is the contact face)
//   "friction": {"tresca": PHI} or {"coulomb": F}                      [N per node, -]
//   "obstacle": {"kind": "plane", "gap": G, "slope": [SX, SY]}
//               {"kind": "sphere", "radius": R, "center": [CX, CY], "gap": G}
//               {"kind": "cylinder", "radius": R, "y": CY, "gap": G}    [m]
//
// Every error is one line naming the file and the key: unknown keys (a
// typo must not silently leave a default), wrong types, bad values (the
// problem's own checks, problem.hpp: validate), unreadable or malformed
// files. The run summary repeats the problem in this same schema under
// "problem", and a summary itself is accepted: its "problem" is read and the
// rest ignored, so `--json run.json` then `--problem run.json` runs the same
// case again.
#pragma once
#include <string>
#include <vector>

#include "core/contact/friction.hpp"
#include "core/fem/problem.hpp"

namespace tresca {

struct ProblemFile {
  ProblemSpec spec;
  bool mesh_given = false;  // "mesh" present
  FrictionLaw friction;     // Tresca (spec.phi) or Coulomb with a coefficient
};

// throws std::invalid_argument with a one-line message
ProblemFile read_problem_file(const std::string& path);
ProblemFile parse_problem(const std::string& text, const std::string& origin = "problem");
// Values per contact node from a CSV file whose header names ix, iy and
// `columns` (in any order; other columns are ignored, so the driver's own
// --contact-csv output qualifies): one row per contact node (1 <= ix <= ex,
// 0 <= iy <= ey), every contact node exactly once, finite numbers. Returns
// one vector per column, in contact-node order; throws std::invalid_argument
// naming `what`, the file, the line and the value.
std::vector<std::vector<real>> read_contact_csv(const std::string& path, const GridDims& g,
                                                const std::vector<std::string>& columns, const std::string& what);
// the gap per contact node (>= 0, metres) from the column `gap`
std::vector<real> read_gap_csv(const std::string& path, const GridDims& g);
// the problem in the file's schema, as JSON text (one line)
std::string problem_json(const ProblemSpec& s, const FrictionLaw& friction);

}  // namespace tresca
