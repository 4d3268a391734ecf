#include "core/fem/problem.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "kernels/element.hpp"

namespace tresca {

namespace {
[[noreturn]] void fail(const std::string& what) { throw std::invalid_argument(what); }
}  // namespace

ProblemScales scales_of(const ProblemSpec& s) {
  const real hx = s.lx / real(s.ex), hy = s.ly / real(s.ey), hz = s.lz / real(s.ez);
  std::array<real, 576> Ke;
  brick_stiffness(hx, hy, hz, s.E, s.nu, Ke.data());
  ProblemScales sc;
  sc.stiffness_min = INFINITY;
  for (int i = 0; i < 24; ++i) sc.stiffness_min = std::min(sc.stiffness_min, Ke[25 * i]);
  for (real k : Ke) sc.stiffness_max = std::max(sc.stiffness_max, std::abs(k));
  const real area[kLoadFaces] = {hy * hz, hx * hz, hx * hz, hx * hy};  // x1, y0, y1, z1
  for (int f = 0; f < kLoadFaces; ++f)
    for (real t : s.traction[f]) sc.force = std::max(sc.force, std::abs(t) * area[f] / 4);
  for (real b : s.body_force) sc.force = std::max(sc.force, std::abs(b) * hx * hy * hz / 8);
  sc.force *= s.load_scale;
  sc.displacement_max = sc.force / sc.stiffness_min;
  sc.displacement_min = sc.force / sc.stiffness_max;
  return sc;
}

bool fits_single_precision(const ProblemScales& sc) {
  auto held = [](real q) { return q >= 1e-28 && q <= 1e31; };
  if (!held(sc.stiffness_max) || !held(sc.stiffness_min)) return false;
  return sc.force == 0 || (held(sc.force) && held(sc.displacement_max) && held(sc.displacement_min));
}

std::array<index, 3> level_dims(int level) {
  const double s = std::pow(2.0, level / 2.0);
  return {index(std::ceil(4 * s - 1e-9)), index(std::ceil(2 * s - 1e-9)), index(std::ceil(2 * s - 1e-9))};
}

ProblemSpec spec_for_level(long long level) {
  if (level < 0 || level > kMaxLevel) {
    std::ostringstream os;
    os << "mesh level " << level << " is out of range (0.." << kMaxLevel << ")";
    fail(os.str());
  }
  ProblemSpec s;
  s.level = int(level);
  auto d = level_dims(int(level));
  s.ex = d[0];
  s.ey = d[1];
  s.ez = d[2];
  return s;
}

ProblemSpec spec_for_dims(index ex, index ey, index ez) {
  ProblemSpec s;
  s.ex = ex;
  s.ey = ey;
  s.ez = ez;
  return s;
}

const char* load_face_name(int f) {
  static const char* names[kLoadFaces] = {"x1", "y0", "y1", "z1"};
  return f >= 0 && f < kLoadFaces ? names[f] : "?";
}

const char* to_string(Obstacle::Kind k) {
  switch (k) {
    case Obstacle::Kind::plane: return "plane";
    case Obstacle::Kind::sphere: return "sphere";
    case Obstacle::Kind::cylinder: return "cylinder";
  }
  return "?";
}

real Obstacle::gap_at(real x, real y) const {
  switch (kind) {
    case Kind::plane: return gap + slope_x * x + slope_y * y;
    case Kind::sphere:
    case Kind::cylinder: {
      const real dx = kind == Kind::sphere ? x - cx : 0, dy = y - cy, r2 = dx * dx + dy * dy;
      // R - sqrt(R^2 - r^2) without the cancellation near the top
      return r2 < radius * radius ? gap + r2 / (radius + std::sqrt(radius * radius - r2)) : kNoObstacle;
    }
  }
  return kNoObstacle;
}

void validate(const ProblemSpec& s) {
  std::ostringstream os;
  os.precision(12);  // nu = 0.49999999 must not print as 0.5
  if (s.ex < 1 || s.ey < 1 || s.ez < 1) {
    os << "element counts " << s.ex << "x" << s.ey << "x" << s.ez << " must all be >= 1";
    fail(os.str());
  }
  if (!(s.E > 0) || !std::isfinite(s.E)) {
    os << "Young's modulus E = " << s.E << " must be positive and finite";
    fail(os.str());
  }
  if (!(s.nu > -1 && s.nu < 0.5)) {
    os << "Poisson ratio nu = " << s.nu << " must lie in (-1, 0.5)";
    fail(os.str());
  }
  const Obstacle& o = s.obstacle;
  if (!(o.gap >= 0) || !std::isfinite(o.gap)) {
    os << "gap = " << o.gap << " must be >= 0 and finite";
    fail(os.str());
  }
  if (o.kind != Obstacle::Kind::plane && (!(o.radius > 0) || !std::isfinite(o.radius))) {
    os << to_string(o.kind) << " radius = " << o.radius << " must be positive and finite";
    fail(os.str());
  }
  if (!std::isfinite(o.slope_x) || !std::isfinite(o.slope_y) || !std::isfinite(o.cx) || !std::isfinite(o.cy)) {
    os << "obstacle parameters must be finite";
    fail(os.str());
  }
  // a plane is linear: it stays below the contact face iff it does at the corners
  for (real x : {s.x0, s.x0 + s.lx})
    for (real y : {s.y0, s.y0 + s.ly})
      if (!(o.gap_at(x, y) >= 0)) {
        os << "the obstacle cuts into the contact face: gap " << o.gap_at(x, y) << " m at (x, y) = (" << x << ", " << y
           << ")";
        fail(os.str());
      }
  for (int f = 0; f < kLoadFaces; ++f)
    for (real t : s.traction[f])
      if (!std::isfinite(t)) {
        os << "traction on face " << load_face_name(f) << " must be finite";
        fail(os.str());
      }
  for (real b : s.body_force)
    if (!std::isfinite(b)) {
      os << "body force must be finite";
      fail(os.str());
    }
  if (!(s.load_scale >= 0) || !std::isfinite(s.load_scale)) {
    os << "load scale = " << s.load_scale << " must be >= 0 and finite";
    fail(os.str());
  }
  if (!(s.phi >= 0) || !std::isfinite(s.phi)) {
    os << "friction bound phi = " << s.phi << " must be >= 0 and finite";
    fail(os.str());
  }
  if (!(s.lx > 0 && s.ly > 0 && s.lz > 0)) {
    os << "box edges " << s.lx << " " << s.ly << " " << s.lz << " must be positive";
    fail(os.str());
  }
  // in double: guards the int64 product in ProblemSpec::nodes() against overflow
  const double nodes = double(s.ex + 1) * double(s.ey + 1) * double(s.ez + 1);
  if (nodes > 4e8) {
    if (s.level >= 0) os << "level " << s.level << ": ";
    os << "mesh " << s.ex << "x" << s.ey << "x" << s.ez << " has " << nodes << " nodes, beyond what this code can address";
    fail(os.str());
  }
}

GridDims grid_of(const ProblemSpec& spec) {
  GridDims g;
  g.ex = spec.ex;
  g.ey = spec.ey;
  g.ez = spec.ez;
  g.lx = spec.lx;
  g.ly = spec.ly;
  g.lz = spec.lz;
  g.x0 = spec.x0;
  g.y0 = spec.y0;
  g.z0 = spec.z0;
  return g;
}

Problem make_problem(const ProblemSpec& spec) {
  validate(spec);
  Problem P;
  P.spec = spec;
  P.grid = grid_of(spec);
  return P;
}

Field<real> load_on(const Problem& P, const Slab& s) {
  HostLaunches host;  // assembled on the host, then moved where the launches run
  const ProblemSpec& spec = P.spec;
  const GridDims& g = P.grid;
  const GridDims& box = s.local;
  const index N = box.nodes(), first = s.y_begin - s.lo, last = first + box.ny();  // global rows [first, last)
  Field<real> load(std::size_t(3 * N), 0.0);
  real* l = load.data();
  // adds v to node (ix, iy, iz) of the whole grid where the slab holds it:
  // every node's terms come in the same order whatever the slab, so each
  // rank's rows hold the whole mesh's values bit for bit
  auto add = [&](index ix, index iy, index iz, const std::array<real, 3>& v) {
    if (iy < first || iy >= last) return;
    const index n = box.node(ix, iy - first, iz);
    for (int a = 0; a < 3; ++a) l[a * N + n] += v[a];
  };
  // surface tractions: face f's quads, each node of a quad gets area/4
  const real L = spec.load_scale;
  auto face = [&](int f, index n1, index n2, real area, auto node) {
    std::array<real, 3> v;
    for (int a = 0; a < 3; ++a) v[a] = L * spec.traction[f][a] * area / 4;
    for (index j = 0; j < n2; ++j)
      for (index i = 0; i < n1; ++i)
        for (int k = 0; k < 4; ++k) node(i + (k & 1), j + (k >> 1), v);
  };
  face(kLoadX1, g.ey, g.ez, g.hy() * g.hz(), [&](index j, index k, const auto& v) { add(g.ex, j, k, v); });
  face(kLoadY0, g.ex, g.ez, g.hx() * g.hz(), [&](index i, index k, const auto& v) { add(i, 0, k, v); });
  face(kLoadY1, g.ex, g.ez, g.hx() * g.hz(), [&](index i, index k, const auto& v) { add(i, g.ey, k, v); });
  face(kLoadZ1, g.ex, g.ey, g.hx() * g.hy(), [&](index i, index j, const auto& v) { add(i, j, g.ez, v); });
  // body force: each brick gives volume/8 to each of its 8 nodes (the bricks
  // with a node in the slab's rows)
  if (spec.body_force != std::array<real, 3>{0, 0, 0}) {
    const real q = g.hx() * g.hy() * g.hz() / 8;
    std::array<real, 3> v;
    for (int a = 0; a < 3; ++a) v[a] = L * spec.body_force[a] * q;
    for (index ez = 0; ez < g.ez; ++ez)
      for (index ey = std::max<index>(0, first - 1); ey < std::min(g.ey, last); ++ey)
        for (index ex = 0; ex < g.ex; ++ex)
          for (int k = 0; k < 8; ++k) add(ex + (k & 1), ey + ((k >> 1) & 1), ez + (k >> 2), v);
  }
  for (index iz = 0; iz < box.nz(); ++iz)
    for (index iy = 0; iy < box.ny(); ++iy)
      for (int a = 0; a < 3; ++a) l[a * N + box.node(0, iy, iz)] = 0;
  load.move_to(host.space_before());
  return load;
}

Field<real> whole_load(const Problem& P) { return load_on(P, make_slab(P.grid, 0, 1)); }

double estimated_memory_bytes(const ProblemSpec& s) {
  const double n = double(s.nodes());
  // fine-grid vectors of 3n doubles: Steklov buffers and the load 5, inner
  // CG 4, the V-cycle's work vectors (float: b, x, r, d; shared by the two
  // multigrids) and each multigrid's dinv, Newton's body and the step's
  // side products 3, set-up temporaries; 17 x (1 + 1/7) of them, coarse
  // levels included, and 64 MB for the program bound the measured peak
  // (17.6 vectors at level 12, 17.2 at 13; perf/RESULTS.md §0u)
  return 17.0 * 3 * n * 8 * (1 + 1.0 / 7) + 64e6;
}

double estimated_memory_bytes_per_rank(const ProblemSpec& s, int ranks) {
  if (ranks <= 1) return estimated_memory_bytes(s);
  return estimated_memory_bytes(s) / ranks + 128e6;
}

}  // namespace tresca
