// Coulomb friction, both ways: the bound lagged by one Newton step
// (NewtonOptions::coulomb, the default) and the fixed point of Tresca solves
// (core/contact/coulomb.hpp). The converged solution is a fixed point of
// Tresca, both methods agree, F = 0 is frictionless, and the report is
// honest when the fixed point is cut short.
#include <gtest/gtest.h>

#include <cmath>

#include "core/contact/run.hpp"
#include "test_helpers.hpp"

namespace tresca {

namespace {
using Method = RunOptions::CoulombMethod;
RunResult solve(const ProblemSpec& spec, real F, bool nested = true, Method m = Method::lagged) {
  RunOptions o;
  o.coulomb_method = m;
  o.recover_interior = false;
  o.coulomb = F;
  o.nested = nested;
  o.nested_min_contact_nodes = 40;
  return run_tresca(spec, o);
}
}  // namespace

void fixed_point_of_tresca(Method method) {
  // 32x16x16, F = 1.5: nodes stick, slide and separate (at F = 0.8 none
  // sticks on this mesh). Re-solving Tresca from scratch with
  // phi_i = F lambda_i of the Coulomb solution reproduces it.
  const ProblemSpec spec = spec_for_dims(32, 16, 16);
  const real F = 1.5;
  const RunResult C = solve(spec, F, true, method);
  ASSERT_TRUE(C.converged()) << C.reason();
  ASSERT_TRUE(C.coulomb);
  if (method == Method::fixed_point) {
    EXPECT_GT(C.coulomb_loop.iterations, 1);
  }
  // the Coulomb Newton step converges by itself; at F = 1.5 the lagged
  // bound may oscillate on this mesh, and then the fixed point takes over
  if (method != Method::lagged) {
    EXPECT_FALSE(C.coulomb_fallback);
  }
  EXPECT_GT(C.report.sticking, 0);
  EXPECT_GT(C.report.sliding, 0);
  EXPECT_GT(C.report.separated, 0);
  const index p = C.problem->contact_nodes();
  RunOptions o;
  o.recover_interior = false;
  o.nested = false;
  o.contact = ContactConditions::uniform(p, 0, 0);
  for (index i = 0; i < p; ++i) o.contact.phi[i] = F * std::max(real(0), C.newton.lambda[i]);
  const RunResult T = run_tresca(spec, o);
  ASSERT_TRUE(T.converged());
  // the fixed point stops at a relative change of 1e-6 in phi
  EXPECT_LT(test::max_abs_diff(T.newton.u, C.newton.u), 1e-5 * test::max_abs(C.newton.u));
  EXPECT_LT(test::max_abs_diff(T.newton.lambda, C.newton.lambda), 1e-5 * test::max_abs(C.newton.lambda));
  EXPECT_TRUE(T.report.status == C.report.status);
  EXPECT_LT(C.coulomb_consistency, 1e-5 * F * test::max_abs(C.newton.lambda));
  // and the friction law holds with phi_i = F lambda_i: |r_t| <= F lambda on
  // every node, to the fixed point's tolerance 1e-6 max phi (twice, for
  // the last solve's own change)
  const real slack = 2e-6 * F * test::max_abs(C.newton.lambda) + 1e-3;
  for (index i = 0; i < p; ++i)
    EXPECT_LE(std::hypot(C.report.r[i], C.report.r[p + i]), F * std::max(real(0), C.newton.lambda[i]) + slack) << i;
}

TEST(Coulomb, LaggedBoundConvergesToAFixedPointOfTresca) { fixed_point_of_tresca(Method::lagged); }
TEST(Coulomb, FixedPointConvergesToAFixedPointOfTresca) { fixed_point_of_tresca(Method::fixed_point); }
TEST(Coulomb, NewtonConvergesToAFixedPointOfTresca) { fixed_point_of_tresca(Method::newton); }

TEST(Coulomb, AllThreeMethodsAgree) {
  const ProblemSpec spec = spec_for_dims(24, 12, 12);
  const RunResult b = solve(spec, 0.8, true, Method::fixed_point);
  ASSERT_TRUE(b.converged());
  for (Method m : {Method::lagged, Method::newton}) {
    const RunResult a = solve(spec, 0.8, true, m);
    ASSERT_TRUE(a.converged()) << to_string(m);
    EXPECT_FALSE(a.coulomb_fallback) << to_string(m);
    EXPECT_LT(test::max_abs_diff(a.newton.u, b.newton.u), 1e-5 * test::max_abs(b.newton.u)) << to_string(m);
    EXPECT_LT(test::max_abs_diff(a.newton.lambda, b.newton.lambda), 1e-5 * test::max_abs(b.newton.lambda)) << to_string(m);
    EXPECT_TRUE(a.report.status == b.report.status) << to_string(m);
  }
}

// The Newton step that differentiates phi = F lambda converges in fewer
// steps than the lagged bound, and ends superlinearly (level 7, F = 0.8:
// measured 4 steps against 19)
TEST(Coulomb, NewtonStepsAreFewAndEndSuperlinearly) {
  const ProblemSpec spec = spec_for_level(7);
  const RunResult a = solve(spec, 0.8, true, Method::lagged), n = solve(spec, 0.8, true, Method::newton);
  ASSERT_TRUE(a.converged());
  ASSERT_TRUE(n.converged());
  EXPECT_LE(2 * n.newton.iterations, a.newton.iterations);
  const std::vector<real>& h = n.newton.history;
  ASSERT_GE(h.size(), 3u);
  EXPECT_LT(h[h.size() - 1] / h[h.size() - 2], 1e-2);
  EXPECT_LT(test::max_abs_diff(a.newton.lambda, n.newton.lambda), 1e-5 * test::max_abs(n.newton.lambda));
}

TEST(Coulomb, ZeroCoefficientIsFrictionless) {
  ProblemSpec spec = spec_for_dims(16, 8, 8);
  const RunResult C = solve(spec, 0);
  spec.phi = 0;
  RunOptions o;
  o.recover_interior = false;
  const RunResult T = run_tresca(spec, o);
  ASSERT_TRUE(C.converged());
  ASSERT_TRUE(T.converged());
  EXPECT_LT(test::max_abs_diff(T.newton.u, C.newton.u), 1e-8 * test::max_abs(T.newton.u));
  EXPECT_LT(test::max_abs_diff(T.newton.lambda, C.newton.lambda), 1e-8 * test::max_abs(T.newton.lambda));
}

TEST(Coulomb, NestedAndColdReachTheSameSolution) {
  const ProblemSpec spec = spec_for_dims(16, 8, 8);
  const RunResult a = solve(spec, 0.3, true), b = solve(spec, 0.3, false);
  ASSERT_TRUE(a.converged());
  ASSERT_TRUE(b.converged());
  EXPECT_FALSE(a.nested.empty());
  EXPECT_LT(test::max_abs_diff(a.newton.u, b.newton.u), 1e-5 * test::max_abs(b.newton.u));
  EXPECT_TRUE(a.report.status == b.report.status);
}

TEST(Coulomb, ReportsAnIterationLimitOfTheFixedPoint) {
  // one Tresca solve cannot make phi = F lambda consistent: not converged, and said so
  const Problem P = make_problem(spec_for_dims(8, 4, 4));
  SteklovPoincare S(P);
  CoulombOptions co;
  co.F = 0.5;
  co.max_iterations = 1;
  const CoulombResult C =
      coulomb_fixed_point(S, ContactConditions::uniform(P.contact_nodes(), 0, 0), co, NewtonOptions{});
  EXPECT_FALSE(C.converged());
  EXPECT_EQ(C.reason, CoulombReason::iteration_limit);
  EXPECT_EQ(C.iterations, 1);
  ASSERT_EQ(C.changes.size(), 1u);
  EXPECT_GT(C.changes[0], 0.5);  // from frictionless to F lambda: phi changes entirely
  co.F = -1;
  EXPECT_THROW(coulomb_fixed_point(S, ContactConditions::uniform(P.contact_nodes(), 0, 0), co, NewtonOptions{}),
               std::invalid_argument);
}

}  // namespace tresca
