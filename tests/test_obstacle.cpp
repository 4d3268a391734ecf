// Shaped rigid obstacles (problem.hpp: Obstacle): the gaps they give, the
// checks on their parameters, and contact where, and as much as, they allow.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "core/contact/run.hpp"
#include "kernels/contact_maps.hpp"

namespace tresca {

TEST(Obstacle, GapsFollowTheShapes) {
  Obstacle plane;
  plane.gap = 0.01;
  plane.slope_x = 0.02;
  plane.slope_y = -0.005;
  EXPECT_DOUBLE_EQ(plane.gap_at(1.5, 0.5), 0.01 + 0.03 - 0.0025);
  Obstacle sphere;
  sphere.kind = Obstacle::Kind::sphere;
  sphere.radius = 2;
  sphere.cx = 1;
  sphere.cy = 0.5;
  sphere.gap = 0.001;
  EXPECT_DOUBLE_EQ(sphere.gap_at(1, 0.5), 0.001);                              // the top
  EXPECT_NEAR(sphere.gap_at(1.6, 1.3), 0.001 + 2 - std::sqrt(4 - 1.0), 1e-15);  // rho = 1
  EXPECT_EQ(sphere.gap_at(3.5, 0.5), Obstacle::kNoObstacle);                   // not under the point
  Obstacle cyl = sphere;
  cyl.kind = Obstacle::Kind::cylinder;
  EXPECT_DOUBLE_EQ(cyl.gap_at(-7, 0.5), 0.001);  // the axis runs along x
  EXPECT_NEAR(cyl.gap_at(0.3, 1.5), 0.001 + 2 - std::sqrt(3.0), 1e-15);
}

TEST(Obstacle, ParametersAreChecked) {
  ProblemSpec s = spec_for_dims(4, 2, 2);
  s.obstacle.slope_x = -0.01;  // gap 0 at x = 0 falls below the face along x
  EXPECT_THROW(validate(s), std::invalid_argument);
  s.obstacle.gap = 0.02;  // 0.02 - 0.01 * 2 = 0 at the far end: touching is allowed
  EXPECT_NO_THROW(validate(s));
  s.obstacle = Obstacle{};
  s.obstacle.kind = Obstacle::Kind::sphere;
  EXPECT_THROW(validate(s), std::invalid_argument);  // radius 0
  s.obstacle.radius = 1;
  EXPECT_NO_THROW(validate(s));
}

TEST(Obstacle, SphereContactStaysOverTheSphereAndGrowsWithTheLoad) {
  // a sphere of radius 2 under the middle of the face, touching it: the
  // contact set is a patch around the top that grows with the load
  ProblemSpec spec = spec_for_dims(24, 12, 12);
  spec.phi = 3e6;
  spec.obstacle.kind = Obstacle::Kind::sphere;
  spec.obstacle.radius = 2;
  spec.obstacle.cx = 1.2;
  spec.obstacle.cy = 0.5;
  index previous = 0;
  for (real scale : {0.25, 0.5, 1.0}) {
    spec.load_scale = scale;
    RunOptions o;
    o.recover_interior = false;
    const RunResult R = run_tresca(spec, o);
    ASSERT_TRUE(R.converged()) << R.reason();
    const Problem& P = *R.problem;
    const index p = P.contact_nodes();
    real rho_max = 0;
    for (index i = 0; i < p; ++i)
      if (R.report.status[i] & kContact) {
        const real x = real(1 + i % P.grid.ex) * P.grid.hx(), y = real(i / P.grid.ex) * P.grid.hy();
        rho_max = std::max(rho_max, std::hypot(x - 1.2, y - 0.5));
        // in contact: the body touches the sphere, u_z = -gap
        EXPECT_NEAR(R.newton.u[2 * p + i], -R.contact.gap[i], 1e-9) << i;
      }
    EXPECT_GT(R.report.active, previous) << "load scale " << scale;
    EXPECT_GT(R.report.separated, 0);
    EXPECT_LT(rho_max, 2.0);
    EXPECT_LT(R.report.uz_violation, 1e-12);
    previous = R.report.active;
  }
}

// Contact patch test (issue 10). A uniform state that the clamped face
// x = 0 allows: uniaxial strain u = (a (x - x0), 0, 0), a < 0, held by the
// tractions of its stress on x1, y0, y1 and z1 (sigma_xx = (lambda + 2 mu) a,
// sigma_yy = sigma_zz = lambda a). The block is pressed onto the plane with
// the uniform pressure p = -lambda a, and its bottom slides (u_x = a x) with
// zero shear, which frictionless contact (phi = 0) allows. Trilinear
// elements hold linear fields exactly, so the discrete solution is exact:
// every contact node in contact and sliding, its force p times its nodal
// area (edges half, corners a quarter), u = (a x, 0, 0) in the whole body.
// (Stick and slip under a tangential traction need a block free to slide:
// with x = 0 clamped no uniform state has friction on the bottom.)
TEST(ContactPatch, UniformPressureGivesNodalForcesOfPressureTimesArea) {
  for (const auto& dims : {std::array<index, 3>{8, 4, 4}, std::array<index, 3>{7, 3, 5}}) {
    ProblemSpec spec = spec_for_dims(dims[0], dims[1], dims[2]);
    spec.phi = 0;
    const real a = -1e-3;
    const real lam = spec.E * spec.nu / ((1 + spec.nu) * (1 - 2 * spec.nu)), mu = spec.E / (2 * (1 + spec.nu));
    const real sxx = (lam + 2 * mu) * a, syy = lam * a, szz = lam * a;
    spec.traction[kLoadX1] = {sxx, 0, 0};
    spec.traction[kLoadY0] = {0, -syy, 0};
    spec.traction[kLoadY1] = {0, syy, 0};
    spec.traction[kLoadZ1] = {0, 0, szz};
    spec.body_force = {0, 0, 0};
    const RunResult R = run_tresca(spec, RunOptions{});
    ASSERT_TRUE(R.converged()) << R.reason();
    const Problem& P = *R.problem;
    const GridDims& g = P.grid;
    const index p = P.contact_nodes(), N = g.nodes();
    const real pressure = -szz, ux_max = std::abs(a) * spec.lx;
    for (index c = 0; c < p; ++c) {
      const index ix = 1 + c % g.ex, iy = c / g.ex;
      const real area = g.hx() * g.hy() * (ix == g.ex ? 0.5 : 1) * ((iy == 0 || iy == g.ey) ? 0.5 : 1);
      EXPECT_NEAR(R.newton.lambda[c], pressure * area, 1e-8 * pressure * area) << "node " << ix << "," << iy;
      EXPECT_NEAR(R.newton.u[c], a * ix * g.hx(), 1e-8 * ux_max);
      EXPECT_NEAR(R.newton.u[p + c], 0, 1e-8 * ux_max);
      EXPECT_NEAR(R.newton.u[2 * p + c], 0, 1e-8 * ux_max);
      EXPECT_NEAR(R.report.r[c], 0, 1e-8 * pressure * area);  // no friction force
      EXPECT_TRUE(R.report.status[c] & kContact);
      EXPECT_FALSE(R.report.status[c] & kStick);
    }
    for (index iz = 0; iz < g.nz(); ++iz)
      for (index iy = 0; iy < g.ny(); ++iy)
        for (index ix = 0; ix < g.nx(); ++ix) {
          const index n = g.node(ix, iy, iz);
          ASSERT_NEAR(R.u_full[n], a * ix * g.hx(), 1e-8 * ux_max) << ix << "," << iy << "," << iz;
          ASSERT_NEAR(R.u_full[N + n], 0, 1e-8 * ux_max);
          ASSERT_NEAR(R.u_full[2 * N + n], 0, 1e-8 * ux_max);
        }
  }
}

// Stick and slip under a tangential traction (issue 10): a pressure and a
// shear on the top face. Where every contact node sticks the contact face
// does not move, so the exact answer is the clamped one: u_c = 0 and the
// contact forces r = S u_c - b̃ = -b̃, the condensed load. With the bound of
// each node above its clamped shear force, phi_i = kappa |b̃_τ,i|, kappa >= 1,
// that is the solution; with kappa = 0.5 no node can stick and every one
// slides with its friction force equal to its bound. (From x0 = 0 Newton in
// the diagonal metric with full steps cycled between two active sets for
// 1 < kappa <= 2 on this mesh; the line search ends the cycle.)
TEST(ContactPatch, ShearBelowTheFrictionLimitSticksAboveItSlides) {
  ProblemSpec spec = spec_for_dims(8, 4, 4);
  spec.traction = {};
  spec.traction[kLoadZ1] = {2e7, 0, -1e8};  // shear along x and pressure on the top
  const Problem P = make_problem(spec);
  SteklovPoincare S(P);
  Field<real> b;
  ASSERT_TRUE(S.condensed_load(1e-13, b).ok());
  const index p = P.contact_nodes();
  for (index c = 0; c < p; ++c) ASSERT_LT(b[2 * p + c], 0) << "the load presses every contact node";
  const real bmax = std::abs(*std::max_element(b.begin(), b.end(), [](real x, real y) { return std::abs(x) < std::abs(y); }));
  const real ushear = bmax / spec.E;  // a displacement scale of these forces [m]
  auto solve = [&](real kappa) {
    RunOptions o;
    o.recover_interior = false;
    o.contact = ContactConditions::uniform(p, 0, 0);
    for (index c = 0; c < p; ++c) o.contact.phi[c] = kappa * std::hypot(b[c], b[p + c]);
    return run_tresca(spec, o);
  };
  for (real kappa : {1.01, 2.0, 1e3}) {
    const RunResult R = solve(kappa);
    ASSERT_TRUE(R.converged()) << "kappa " << kappa << ": " << R.reason();
    EXPECT_LE(R.newton.iterations, 10) << "kappa " << kappa;
    for (index c = 0; c < p; ++c) {
      EXPECT_TRUE(R.report.status[c] & kStick) << c;
      EXPECT_TRUE(R.report.status[c] & kContact) << c;
      for (int a = 0; a < 3; ++a) EXPECT_NEAR(R.newton.u[a * p + c], 0, 1e-10 * ushear) << c;
      for (int a = 0; a < 3; ++a) EXPECT_NEAR(R.report.r[a * p + c], -b[a * p + c], 1e-8 * bmax) << c;
      EXPECT_NEAR(R.newton.lambda[c], -b[2 * p + c], 1e-8 * bmax);
    }
  }
  // kappa = 0.5: the clamped forces exceed every bound twice, the face must
  // slide; the shear then redistributes, and where it falls below the bound
  // a node may stick again (measured: 3 of 40). Every sliding node carries
  // exactly its bound, every sticking one at most that.
  const RunResult R = solve(0.5);
  ASSERT_TRUE(R.converged()) << R.reason();
  index sliding = 0;
  for (index c = 0; c < p; ++c) {
    const real phi = 0.5 * std::hypot(b[c], b[p + c]), rt = std::hypot(R.report.r[c], R.report.r[p + c]);
    EXPECT_TRUE(R.report.status[c] & kContact) << c;
    if (R.report.status[c] & kStick) {
      EXPECT_LE(rt, phi * (1 + 1e-8)) << c;
    } else {
      ++sliding;
      EXPECT_NEAR(rt, phi, 1e-8 * phi) << c;
    }
  }
  EXPECT_GE(sliding, p - 5);
}

}  // namespace tresca
