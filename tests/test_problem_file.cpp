// Problem files (core/io/problem_file.hpp): defaults, every key read back,
// the loads they give, and one-line errors that name the key; the scales of
// a problem (problem.hpp: scales_of) and where single precision holds them.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numeric>
#include <utility>
#include <vector>

#include "core/io/problem_file.hpp"

namespace tresca {

namespace {
// the error message of parsing `text`, or "" if it parses
std::string error_of(const std::string& text) {
  try {
    parse_problem(text, "case.json");
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(ProblemFile, EmptyFileIsTheSeedBenchmark) {
  const ProblemFile f = parse_problem("// nothing but a comment\n{}");
  const ProblemSpec d;
  EXPECT_FALSE(f.mesh_given);
  EXPECT_FALSE(f.friction.is_coulomb());
  EXPECT_EQ(f.spec.E, d.E);
  EXPECT_EQ(f.spec.phi, d.phi);
  EXPECT_EQ(f.spec.traction, d.traction);
  EXPECT_EQ(f.spec.lz, d.lz);
}

TEST(ProblemFile, EveryKeyIsReadAndWrittenBackTheSame) {
  ProblemSpec s = spec_for_dims(7, 5, 3);
  s.lx = 1.5, s.ly = 0.7, s.lz = 0.3, s.x0 = -1, s.y0 = 2, s.z0 = 0.05;
  s.E = 7e10, s.nu = 0.33;
  s.traction = {{{1e6, 2e6, 3e6}, {0, 0, 0}, {4e5, 0, -1}, {0, 0, -2e7}}};
  s.body_force = {0, 1e3, -7.7e4};
  s.load_scale = 0.75;
  s.obstacle.kind = Obstacle::Kind::sphere;
  s.obstacle.radius = 3, s.obstacle.cx = -0.2, s.obstacle.cy = 2.3, s.obstacle.gap = 0.01;
  const ProblemFile f = parse_problem(problem_json(s, coulomb_friction(0.4)));
  const ProblemSpec& r = f.spec;
  EXPECT_TRUE(f.mesh_given);
  EXPECT_TRUE(f.friction.is_coulomb());
  EXPECT_EQ(f.friction.F, 0.4);
  EXPECT_EQ(r.ex, 7);
  EXPECT_EQ(r.ey, 5);
  EXPECT_EQ(r.ez, 3);
  EXPECT_EQ(r.lx, 1.5);
  EXPECT_EQ(r.y0, 2);
  EXPECT_EQ(r.z0, 0.05);
  EXPECT_EQ(r.E, 7e10);
  EXPECT_EQ(r.nu, 0.33);
  EXPECT_EQ(r.traction, s.traction);
  EXPECT_EQ(r.body_force, s.body_force);
  EXPECT_EQ(r.load_scale, 0.75);
  EXPECT_EQ(r.obstacle.kind, Obstacle::Kind::sphere);
  EXPECT_EQ(r.obstacle.radius, 3);
  EXPECT_EQ(r.obstacle.cx, -0.2);
  EXPECT_EQ(r.obstacle.cy, 2.3);
  EXPECT_EQ(r.obstacle.gap, 0.01);
  // and a Tresca bound, a cylinder and a tilted plane
  s.phi = 5e5;
  s.obstacle = Obstacle{};
  s.obstacle.kind = Obstacle::Kind::cylinder, s.obstacle.radius = 1, s.obstacle.cy = 2.4;
  ProblemFile g = parse_problem(problem_json(s, tresca_friction()));
  EXPECT_FALSE(g.friction.is_coulomb());
  EXPECT_EQ(g.spec.phi, 5e5);
  EXPECT_EQ(g.spec.obstacle.kind, Obstacle::Kind::cylinder);
  EXPECT_EQ(g.spec.obstacle.cy, 2.4);
  s.obstacle = Obstacle{};
  s.obstacle.gap = 0.1, s.obstacle.slope_x = 0.01, s.obstacle.slope_y = -0.02;
  g = parse_problem(problem_json(s, tresca_friction()));
  EXPECT_EQ(g.spec.obstacle.kind, Obstacle::Kind::plane);
  EXPECT_EQ(g.spec.obstacle.slope_y, -0.02);
}

TEST(ProblemFile, LoadsAreConsistentNodalForces) {
  // a traction on y = y0 and a body force: the nodal loads add up to
  // traction x area and force x volume, less the shares of the clamped
  // x = x0 nodes (half of the first layer of elements along x)
  const ProblemFile f = parse_problem(R"({"mesh": {"dims": [4, 3, 2]}, "box": {"lengths": [2, 1, 0.5]},
      "loads": {"traction": {"y0": [0, 3e6, 0]}, "body_force": [0, 0, -8e4], "scale": 0.5}})");
  const Problem P = make_problem(f.spec);
  const index N = P.nodes();
  const real keep = 1 - 0.5 / 4;
  const Field<real> load = whole_load(P);
  const real fy = std::accumulate(load.begin() + N, load.begin() + 2 * N, 0.0);
  const real fz = std::accumulate(load.begin() + 2 * N, load.end(), 0.0);
  EXPECT_NEAR(fy, 0.5 * 3e6 * 2 * 0.5 * keep, 1e-6);
  EXPECT_NEAR(fz, 0.5 * -8e4 * 2 * 1 * 0.5 * keep, 1e-6);
  EXPECT_EQ(std::accumulate(load.begin(), load.begin() + N, 0.0), 0.0);  // no x1 traction: "traction" replaces all
  // on the rows of any slab (ghost rows included), the whole mesh's values bit for bit
  for (int ranks : {2, 3})
    for (int rank = 0; rank < ranks; ++rank) {
      const Slab s = make_slab(P.grid, rank, ranks);
      const Field<real> part = load_on(P, s);
      ASSERT_EQ(part.size(), std::size_t(3 * s.local.nodes()));
      std::vector<real> expect(part.size());
      global_to_local(s, load.data(), expect.data());
      EXPECT_EQ(std::vector<real>(part.begin(), part.end()), expect) << "rank " << rank << " of " << ranks;
    }
}

TEST(ProblemScales, MatchTheClosedFormsAndSayWhereSinglePrecisionHolds) {
  // cubes of edge h = 0.25: the Q1 brick's diagonal is h (lambda + 4 mu) / 9
  // (each integral of a squared shape-function derivative is h / 9); the
  // x1 face's traction 5e8 Pa gives a node 5e8 h^2 / 4 from each element
  ProblemSpec s = spec_for_dims(8, 4, 4);
  s.lz = 1;
  const real h = 0.25, mu = s.E / (2 * (1 + s.nu)), lambda = s.E * s.nu / ((1 + s.nu) * (1 - 2 * s.nu));
  const ProblemScales sc = scales_of(s);
  EXPECT_NEAR(sc.stiffness_min, h * (lambda + 4 * mu) / 9, 1e-9 * sc.stiffness_min);
  EXPECT_GE(sc.stiffness_max, sc.stiffness_min);
  EXPECT_LT(sc.stiffness_max, 2 * sc.stiffness_min);  // (the diagonal dominates the brick's entries)
  EXPECT_NEAR(sc.force, 5e8 * h * h / 4, 1e-6);
  EXPECT_NEAR(sc.displacement_max, sc.force / sc.stiffness_min, 1e-12);
  EXPECT_TRUE(fits_single_precision(sc));
  // E = 1e40 Pa overflows a float, E = 1e-40 Pa and loads of 1e-40 underflow
  // (measured: RESULTS.md §0ze), as do loads scaled by 1e40; without load
  // any material fits
  for (auto change : std::vector<std::pair<real, real>>{{1e40, 1}, {1e-40, 1}, {2.1e9, 1e-40}, {2.1e9, 1e40}}) {
    ProblemSpec t = s;
    t.E = change.first;
    t.load_scale = change.second;
    EXPECT_FALSE(fits_single_precision(scales_of(t))) << "E " << t.E << " load scale " << t.load_scale;
  }
  s.load_scale = 0;
  EXPECT_EQ(scales_of(s).force, 0);
  EXPECT_TRUE(fits_single_precision(scales_of(s)));
}

TEST(ProblemFile, ErrorsNameTheKey) {
  EXPECT_NE(error_of(R"({"materail": {}})").find("'materail' is not a known key"), std::string::npos);
  EXPECT_NE(error_of(R"({"material": {"E": "steel"}})").find("'material.E' must be a number"), std::string::npos);
  EXPECT_NE(error_of(R"({"material": {"nu": 0.7}})").find("nu"), std::string::npos);
  EXPECT_NE(error_of(R"({"box": {"lengths": [1, -2, 1]}})").find("'box.lengths' must be positive"), std::string::npos);
  EXPECT_NE(error_of(R"({"box": {"lengths": [1, 2]}})").find("array of 3 numbers"), std::string::npos);
  EXPECT_NE(error_of(R"({"mesh": {"dims": [4, 0, 2]}})").find("'mesh.dims[1]' must be >= 1"), std::string::npos);
  EXPECT_NE(error_of(R"({"mesh": {"dims": [4, 2.5, 2]}})").find("'mesh.dims[1]' must be an integer"), std::string::npos);
  EXPECT_NE(error_of(R"({"mesh": {"level": 4, "dims": [4, 2, 2]}})").find("exactly one"), std::string::npos);
  EXPECT_NE(error_of(R"({"mesh": {"level": 99}})").find("mesh.level"), std::string::npos);
  EXPECT_NE(error_of(R"({"loads": {"traction": {"x0": [1, 0, 0]}}})").find("'loads.traction.x0' is not a known key"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"friction": {"coulomb": -0.1}})").find("'friction.coulomb' must be >= 0"), std::string::npos);
  EXPECT_NE(error_of(R"({"friction": {}})").find("exactly one"), std::string::npos);
  EXPECT_NE(error_of(R"({"obstacle": {"kind": "cone"}})").find("'cone' is not"), std::string::npos);
  EXPECT_NE(error_of(R"({"obstacle": {"kind": "sphere", "radius": 1}})").find("needs 'radius' and 'center'"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"obstacle": {"kind": "plane", "slope": [-0.1, 0]}})").find("cuts into the contact face"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"mesh": {"level": 4},})").find("is not valid JSON"), std::string::npos);
  // a key twice in one object: JSON keeps the last, which must not drop the first silently
  EXPECT_NE(error_of(R"({"mesh": {"level": 4}, "mesh": {"level": 5}})").find("'mesh' is given twice"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"loads": {"traction": {"z1": [0, 0, 1], "z1": [0, 0, 2]}}})")
                .find("'loads.traction.z1' is given twice"),
            std::string::npos);
  EXPECT_EQ(error_of(R"({"loads": {"traction": {"z1": [0, 0, 1]}, "body_force": [0, 0, 1]}, "box": {}})"), "");
  EXPECT_EQ(error_of(R"({"mesh": {"level": 4}})"), "");
  for (const std::string& e : {error_of(R"({"materail": {}})"), error_of("[1, 2]")}) {
    EXPECT_EQ(e.rfind("case.json: ", 0), 0u) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
  try {
    read_problem_file("/nonexistent/case.json");
    ADD_FAILURE() << "no error for an unreadable file";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("cannot read problem file '/nonexistent/case.json'"), std::string::npos);
  }
}

TEST(GapFile, ReadsEveryContactNodeAndRejectsTheRest) {
  const Problem P = make_problem(spec_for_dims(3, 2, 2));  // contact nodes ix 1..3, iy 0..2
  const std::string path = ::testing::TempDir() + "/gaps.csv";
  auto write = [&](const std::string& body) {
    std::ofstream f(path);
    f << body;
  };
  std::string good = "ix,iy,gap\n";
  for (int iy = 0; iy <= 2; ++iy)
    for (int ix = 1; ix <= 3; ++ix) good += std::to_string(ix) + "," + std::to_string(iy) + "," + std::to_string(0.01 * ix + 0.1 * iy) + "\n";
  write(good);
  const std::vector<real> g = read_gap_csv(path, P.grid);
  ASSERT_EQ(index(g.size()), P.contact_nodes());
  for (index c = 0; c < P.contact_nodes(); ++c) EXPECT_NEAR(g[c], 0.01 * (1 + c % 3) + 0.1 * (c / 3), 1e-12) << c;
  auto error = [&](const std::string& body) -> std::string {
    write(body);
    try {
      read_gap_csv(path, P.grid);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(error("x,y,gap\n").find("header"), std::string::npos);
  EXPECT_NE(error("ix,iy,gap\n0,0,0.1\n").find("line 2: node (0, 0) is not a contact node"), std::string::npos);
  std::string negative = good;
  negative.replace(negative.find("2,1,"), 8, "2,1,-0.1");
  EXPECT_NE(error(negative).find("the gap at node (2, 1) is negative"), std::string::npos) << error(negative);
  EXPECT_NE(error("ix,iy,gap\n1,0,0.1\n1,0,0.2\n").find("line 3: node (1, 0) is given twice"), std::string::npos);
  EXPECT_NE(error("ix,iy,gap\n1,0,0.1\n").find("gives 1 of the 9 contact nodes"), std::string::npos);
  EXPECT_NE(error("ix,iy,gap\n1;0;0.1\n").find("line 2: has 1 fields, the header 3"), std::string::npos);
  EXPECT_NE(error("ix,iy,gap\n1,0,abc\n").find("line 2: gap 'abc' is not a finite number"), std::string::npos);
  EXPECT_NE(error("ix,iy,gap\n1,0,nan\n").find("not a finite number"), std::string::npos);
  EXPECT_NE(error("ix,iy,gap\n1.5,0,0.1\n").find("node (1.5, 0) is not a contact node"), std::string::npos);
  EXPECT_NE(error("").find("empty"), std::string::npos);
  // columns by name, in any order, others ignored (the driver's own CSV qualifies)
  std::string shuffled = "gap,note,iy,ix\n";
  for (int iy = 0; iy <= 2; ++iy)
    for (int ix = 1; ix <= 3; ++ix)
      shuffled += std::to_string(0.01 * ix + 0.1 * iy) + ",x," + std::to_string(iy) + "," + std::to_string(ix) + "\n";
  write(shuffled);
  EXPECT_EQ(read_gap_csv(path, P.grid), g);
}

}  // namespace tresca
