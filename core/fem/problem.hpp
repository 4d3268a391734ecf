// The benchmark problem of the seed paper (method.md §1).
//
// Prism (0,2)x(0,1)x(0.1,1), E = 2.1e9, nu = 0.277, u = 0 on x = 0,
// tractions (-5e8,0,0) on x = 2 and (0,0,-1e8) on z = 1 (consistent nodal
// loads: each face quad gives traction*area/4 to its 4 nodes), rigid
// foundation under the bottom face z = 0.1 (contact nodes: iz = 0, ix > 0),
// Tresca bound phi per contact node.
//
// Mesh level l: ex = ceil(4*2^(l/2)), ey = ez = ceil(2*2^(l/2)); or explicit
// element counts. Every value can be changed before calling make_problem.
//
// DATA LAYOUT: SoA fields over the grid (grid.hpp); contact node
// c = (ix-1) + ex*iy for the bottom node (ix, iy, 0), p = ex*(ey+1).
#pragma once
#include <array>
#include <string>
#include <vector>

#include "kernels/launch.hpp"
#include "kernels/grid.hpp"
#include "kernels/types.hpp"
#include "core/parallel/slab.hpp"

namespace tresca {

// The rigid obstacle below the contact face (lengths in metres, x and y in
// the box's frame). gap_at(x, y) >= 0 is the vertical distance from the
// contact face to the obstacle under the point (non-penetration
// u_z + gap >= 0, the normal staying z: small deformations and gentle shapes):
//   plane:    gap + slope_x x + slope_y y
//   sphere:   radius R, its top point `gap` below the face at (cx, cy):
//             gap + R - sqrt(R^2 - rho^2), rho the distance from (cx, cy)
//   cylinder: axis along x at y = cy, top line `gap` below the face:
//             gap + R - sqrt(R^2 - (y - cy)^2)
// Where a sphere or cylinder is not under the point the gap is kNoObstacle.
struct Obstacle {
  enum class Kind { plane, sphere, cylinder };
  Kind kind = Kind::plane;
  real gap = 0;
  real slope_x = 0, slope_y = 0;     // plane
  real radius = 0, cx = 0, cy = 0;   // sphere (cx, cy), cylinder (cy)
  static constexpr real kNoObstacle = 1e6;
  real gap_at(real x, real y) const;
};
const char* to_string(Obstacle::Kind k);

// faces that can carry a traction, in ProblemSpec::traction order
enum LoadFace { kLoadX1, kLoadY0, kLoadY1, kLoadZ1, kLoadFaces };
const char* load_face_name(int f);  // "x1", "y0", "y1", "z1"

struct ProblemSpec {
  int level = -1;                  // -1 when dims were given explicitly
  index ex = 0, ey = 0, ez = 0;
  real lx = 2, ly = 1, lz = 0.9;   // box edges
  real x0 = 0, y0 = 0, z0 = 0.1;   // box origin
  real E = 2.1e9, nu = 0.277;
  // surface tractions [Pa] on the faces free to carry them (x = x0 is
  // clamped, z = z0 is the contact face), a body force [N/m^3], all times
  // load_scale; consistent nodal loads (a quad gives traction * area / 4 to
  // each of its nodes, a brick body_force * volume / 8)
  std::array<std::array<real, 3>, kLoadFaces> traction{{{-5e8, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, -1e8}}};
  std::array<real, 3> body_force{0, 0, 0};
  real load_scale = 1;
  real phi = 1;                    // Tresca bound per contact node (a force)
  Obstacle obstacle;               // the rigid obstacle (default: the plane touching the face)

  // sizes follow from the element counts alone (no need to build the problem)
  index nodes() const { return (ex + 1) * (ey + 1) * (ez + 1); }
  index contact_nodes() const { return ex * (ey + 1); }                  // bottom nodes with x > 0
  index free_dofs() const { return 3 * (nodes() - (ey + 1) * (ez + 1)); }  // all but the x = 0 face
};

// Mesh levels 0..kMaxLevel exist (level 20: 3e10 dofs); whether one fits in
// memory is a separate check (cli.hpp: check_memory).
constexpr int kMaxLevel = 20;
// Element counts of mesh level l (method.md §1).
std::array<index, 3> level_dims(int level);
// The one place that checks the level range: throws std::invalid_argument
// naming the value if the level is outside 0..kMaxLevel.
ProblemSpec spec_for_level(long long level);
ProblemSpec spec_for_dims(index ex, index ey, index ez);
// Throws std::invalid_argument naming the offending value.
void validate(const ProblemSpec& s);

// The magnitudes a solve of s computes with: the brick matrix's largest
// entry and smallest diagonal entry [N/m], the largest load one element
// gives a node [N] (0 without load; a node's is up to 8 of them) and the
// displacements it makes at those stiffnesses [m].
struct ProblemScales {
  real stiffness_max = 0, stiffness_min = 0, force = 0, displacement_max = 0, displacement_min = 0;
};
ProblemScales scales_of(const ProblemSpec& s);
// Whether single-precision V-cycles (floats: 1.2e-38 to 3.4e38) hold them
// with room: each within 1e-28 to 1e31. Measured on level 5 (RESULTS.md
// §0ze): they failed (overflow or underflow) at a stiffness of 2e34 and of
// 2e-36 N/m, nodal loads of 8e37 N and displacements of 2e-34 m, and held
// at 2e32, 2e-30, 8e35 and 2e-32. The benchmark's are 4e7 N/m, 8e5 N and
// 2e-2 m.
bool fits_single_precision(const ProblemScales& sc);

// Contact node c = (ix - 1) + ex iy, 1 <= ix <= ex, on the bottom face:
// its grid node and its position (x, y)
inline index contact_grid_node(const GridDims& g, index c) { return g.node(1 + c % g.ex, c / g.ex, 0); }
inline std::array<real, 2> contact_position(const GridDims& g, index c) {
  return {g.x0 + real(1 + c % g.ex) * g.hx(), g.y0 + real(c / g.ex) * g.hy()};
}

struct Problem {
  ProblemSpec spec;
  GridDims grid;
  unsigned dirichlet_faces = kFaceX0;              // K: u = 0 on x = 0
  unsigned interior_faces = kFaceX0 | kFaceZ0;     // K_ii: also the contact face
  index contact_nodes() const { return spec.contact_nodes(); }
  // grid node of contact node c
  index contact_grid_node(index c) const { return tresca::contact_grid_node(grid, c); }
  index nodes() const { return grid.nodes(); }
  index dofs() const { return 3 * grid.nodes(); }
  // unknown displacement dofs (all but the Dirichlet face)
  index free_dofs() const { return spec.free_dofs(); }
};

Problem make_problem(const ProblemSpec& spec);
// The load vector l (SoA, 3 x the slab's box: its ghost rows included) on
// the rows of slab s, where the launches run: made for the rows asked for,
// so no rank holds the whole mesh's; every node's value bit for bit the
// same whatever the slab. whole_load: on the whole grid.
Field<real> load_on(const Problem& P, const Slab& s);
Field<real> whole_load(const Problem& P);
// the mesh of a problem, without building it
GridDims grid_of(const ProblemSpec& spec);

// Rough peak memory of a full tresca solve in bytes (for a warning before large runs).
double estimated_memory_bytes(const ProblemSpec& s);
// ... of one of `ranks` MPI ranks (core/parallel): its share of the
// distributed fields plus 128 MB for what each process holds besides (MPI's
// buffers, the block cache's slack; no rank holds a field of the whole
// mesh); held against the measured peak in perf/RESULTS.md §0u.
double estimated_memory_bytes_per_rank(const ProblemSpec& s, int ranks);

}  // namespace tresca
