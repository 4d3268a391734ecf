// Nested iteration (core/contact/nested.hpp): the transfers between contact
// faces reproduce what they must exactly, and a nested solve reaches the same
// solution as the cold start.
#include <gtest/gtest.h>

#include <cmath>

#include "core/contact/nested.hpp"
#include "core/contact/run.hpp"
#include "core/io/problem_file.hpp"
#include "test_helpers.hpp"

namespace tresca {

namespace {
real node_x(const Problem& P, index c) { return P.grid.x0 + real(1 + c % P.grid.ex) * P.grid.hx(); }
real node_y(const Problem& P, index c) { return P.grid.y0 + real(c / P.grid.ex) * P.grid.hy(); }
}  // namespace

TEST(Nested, CoarserMeshHalvesEveryAxisRoundingUp) {
  const ProblemSpec c = coarser_spec(spec_for_level(7));  // 46x23x23
  EXPECT_EQ(c.ex, 23);
  EXPECT_EQ(c.ey, 12);
  EXPECT_EQ(c.ez, 12);
  EXPECT_EQ(c.level, -1);
  EXPECT_TRUE(has_coarser(spec_for_level(7), 64));
  EXPECT_FALSE(has_coarser(spec_for_dims(8, 4, 4), 64));  // 4x2x2: 12 contact nodes
  EXPECT_TRUE(has_coarser(spec_for_dims(3, 3, 3), 1));     // 2x2x2
  EXPECT_FALSE(has_coarser(spec_for_dims(2, 2, 2), 1));    // 1x1x1 is too coarse
  EXPECT_TRUE(has_coarser(spec_for_dims(100, 1, 1), 64));  // 50x1x1: a bar may stay one element thick
  EXPECT_TRUE(has_coarser(spec_for_dims(64, 32, 2), 64));  // 32x16x1: and a plate
  EXPECT_FALSE(has_coarser(spec_for_dims(2, 20, 20), 1));  // 1x10x10: x keeps 2 elements
  // the default's floor: level 8 (64x32x32) goes down to 8x4x4 (40 contact
  // nodes), not to 4x2x2 (12)
  const index floor = RunOptions{}.nested_min_contact_nodes;
  EXPECT_TRUE(has_coarser(spec_for_dims(16, 8, 8), floor));
  EXPECT_FALSE(has_coarser(spec_for_dims(8, 4, 4), floor));
}

TEST(Nested, ContactAreasTileTheFace) {
  // the contact nodes own the face except the half column at x = 0
  for (auto d : {std::array<index, 3>{6, 3, 2}, std::array<index, 3>{7, 5, 3}}) {
    const Problem P = make_problem(spec_for_dims(d[0], d[1], d[2]));
    real sum = 0;
    for (index c = 0; c < P.contact_nodes(); ++c) sum += contact_area(P.grid, c);
    EXPECT_NEAR(sum, P.grid.lx * P.grid.ly - 0.5 * P.grid.hx() * P.grid.ly, 1e-14);
  }
}

TEST(Nested, ProlongationIsExactForBilinearDisplacementsAndPressures) {
  // bilinear interpolation reproduces u = x (1 + 2y) (zero on x = 0, as the
  // Dirichlet column) and a pressure linear in y, on even and odd meshes
  for (auto d : {std::array<index, 3>{12, 6, 4}, std::array<index, 3>{11, 7, 5}}) {
    const Problem F = make_problem(spec_for_dims(d[0], d[1], d[2]));
    const Problem C = make_problem(coarser_spec(F.spec));
    const index pc = C.contact_nodes(), pf = F.contact_nodes();
    auto u_of = [](int a, real x, real y) { return real(a + 1) * x * (1 + 2 * y); };
    auto p_of = [](real y) { return 3e7 * (1 + 0.5 * y); };
    std::vector<real> uc(3 * pc), lc(pc), uf, lf;
    for (index j = 0; j < pc; ++j) {
      for (int a = 0; a < 3; ++a) uc[a * pc + j] = u_of(a, node_x(C, j), node_y(C, j));
      lc[j] = p_of(node_y(C, j)) * contact_area(C.grid, j);
    }
    prolongate_contact(C.grid, uc, lc, F.grid, uf, lf);
    ASSERT_EQ(index(uf.size()), 3 * pf);
    ASSERT_EQ(index(lf.size()), pf);
    for (index i = 0; i < pf; ++i) {
      for (int a = 0; a < 3; ++a) EXPECT_NEAR(uf[a * pf + i], u_of(a, node_x(F, i), node_y(F, i)), 1e-14) << i;
      EXPECT_NEAR(lf[i], p_of(node_y(F, i)) * contact_area(F.grid, i), 1e-7) << i;
    }
  }
}

TEST(Nested, CoarseConditionsCarryDensities) {
  // even dims: every coarse node sits on a fine node of the same kind (corner,
  // edge, inside), so a uniform bound per node becomes 4x per coarse node
  // (4x the area), and the gap is sampled there exactly
  const Problem F = make_problem(spec_for_dims(12, 6, 4));
  const Problem C = make_problem(coarser_spec(F.spec));
  ContactConditions f = ContactConditions::uniform(F.contact_nodes(), 2.5e5, 0);
  for (index i = 0; i < F.contact_nodes(); ++i) f.gap[i] = 0.01 * node_x(F, i) + 0.002 * node_y(F, i);
  const ContactConditions c = coarse_conditions(F.grid, f, C.grid);
  ASSERT_EQ(index(c.phi.size()), C.contact_nodes());
  for (index j = 0; j < C.contact_nodes(); ++j) {
    EXPECT_NEAR(c.phi[j], 4 * 2.5e5, 1e-6) << j;
    EXPECT_NEAR(c.gap[j], 0.01 * node_x(C, j) + 0.002 * node_y(C, j), 1e-15) << j;
  }
}

// nested and cold start: the same solution (contact values to 1e-6 relative,
// same contact and stick sets), with at most as many fine Newton steps
void nested_equals_cold(real phi, real gap) {
  ProblemSpec spec = spec_for_dims(24, 12, 12);
  spec.phi = phi;
  spec.obstacle.gap = gap;
  RunOptions o;
  o.recover_interior = false;
  o.nested_min_contact_nodes = 40;
  o.nested = false;
  const RunResult cold = run_tresca(spec, o);
  o.nested = true;
  const RunResult nested = run_tresca(spec, o);
  ASSERT_TRUE(cold.newton.converged());
  ASSERT_TRUE(nested.newton.converged());
  ASSERT_EQ(nested.nested.size(), 1u);  // 12x6x6 (84 contact nodes); 6x3x3 would have 24 < 40
  EXPECT_EQ(nested.nested[0].spec.ex, 12);
  EXPECT_TRUE(nested.nested[0].converged);
  EXPECT_LE(nested.newton.iterations, cold.newton.iterations);
  EXPECT_LT(test::max_abs_diff(nested.newton.u, cold.newton.u), 1e-6 * test::max_abs(cold.newton.u));
  EXPECT_LT(test::max_abs_diff(nested.newton.lambda, cold.newton.lambda), 1e-6 * test::max_abs(cold.newton.lambda));
  EXPECT_TRUE(nested.report.status == cold.report.status);
  EXPECT_LT(nested.report.true_residual_relative, 1e-10);
  // the fine mesh's |b̃| from the coarser mesh's K_ii^{-1} l_i, no solve: to a
  // few per cent of the cold start's (Newton's first residual, -b̃)
  EXPECT_TRUE(nested.btilde_estimated);
  EXPECT_FALSE(cold.btilde_estimated);
  EXPECT_NEAR(nested.report.btilde_norm, cold.report.btilde_norm, 0.05 * cold.report.btilde_norm);
  EXPECT_GT(nested.fine_matvecs_total, nested.newton.fine_matvecs);  // the coarse work is counted
}

// Drawn by perf/robustness_sweep.py --seed 7 (RESULTS.md §0zw), full
// digits: a block 5x22x5 lifted off a plane. With coarse meshes down to 8
// contact nodes Newton stopped at a |w| summed from its steps of 9.6e-7 N
// under eps = 1e-6 N, which the final check's fresh r put at 1.005e-6 N:
// kkt_check_failed. A stop whose fresh |w| is above the tolerance now goes
// on from that r (run.cpp: resume_after_check), as one whose KKT fields
// missed did before
TEST(Nested, AStopTheFreshResidualPutsAboveEpsGoesOn) {
  const ProblemFile file = parse_problem(
      R"({"mesh": {"dims": [5, 22, 5]}, "box": {"lengths": [1.5440838202572529, 0.16594516425759093, 1.7502786259650362],
          "origin": [0, 0, 0]}, "material": {"E": 414423585.25161177, "nu": 0.17472525841709607},
          "loads": {"traction": {"z1": [70901.90973831342, -5988.616732168594, 108697.21034192141]}},
          "friction": {"tresca": 2.5196203097623378},
          "obstacle": {"kind": "plane", "gap": 0.006980705270279982, "slope": [0.0004508604229607736, 0.0007526680092407207]}})");
  RunOptions o;
  o.friction = file.friction;
  o.recover_interior = false;
  o.nested_min_contact_nodes = 8;
  const RunResult R = run_tresca(file.spec, o);
  ASSERT_EQ(R.nested.size(), 2u);  // 3x11x3 and 2x6x2 (8 contact nodes)
  EXPECT_TRUE(R.converged()) << R.reason();
  EXPECT_TRUE(R.report.kkt_ok);
  EXPECT_GE(R.resumed_from, 0);  // (4 when written)
  EXPECT_LE(R.report.true_residual_consistent, o.newton.eps);
}

TEST(Nested, SameSolutionAsColdStartAtPaperFriction) { nested_equals_cold(1.0, 0); }
TEST(Nested, SameSolutionAsColdStartWhereNodesStickSlideAndSeparate) { nested_equals_cold(3e6, 0); }
TEST(Nested, SameSolutionAsColdStartWithAGap) { nested_equals_cold(1e7, 0.02); }

}  // namespace tresca
