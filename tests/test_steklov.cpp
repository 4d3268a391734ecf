// The matrix-free Steklov–Poincaré operator, condensed load and interior
// recovery against a dense Schur complement computed directly from the
// assembled K on small meshes.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "core/fem/assembly.hpp"
#include "core/contact/steklov.hpp"
#include "dense_reference.hpp"
#include "test_helpers.hpp"

namespace tresca {

namespace {
// u (3N) is the body at contact values uc: uc on the contact face and the
// dense interior solve K_ii^{-1}(l_i - K_ic uc) inside
void expect_dense_body(const DenseSchur& d, const std::vector<real>& uc, const std::vector<real>& u) {
  Eigen::Map<const Eigen::VectorXd> ucv(uc.data(), Eigen::Index(uc.size()));
  const Eigen::VectorXd ui = Eigen::LDLT<Eigen::MatrixXd>(d.Kii).solve(d.li - d.Kic * ucv);
  real err = 0;
  for (size_t r = 0; r < d.idof.size(); ++r) err = std::max(err, std::abs(u[d.idof[r]] - ui[r]));
  EXPECT_LT(err, 1e-9 * ui.cwiseAbs().maxCoeff());
  for (size_t r = 0; r < d.cdof.size(); ++r) EXPECT_EQ(u[d.cdof[r]], uc[r]);
}
}  // namespace

TEST(SteklovPoincare, MatchesDenseSchurComplementAndIsSPD) {
  const index sizes[][3] = {{4, 2, 3}, {5, 3, 2}};
  for (auto& s : sizes) {
    const Problem P = make_problem(spec_for_dims(s[0], s[1], s[2]));
    MGOptions mo;
    mo.coarse_nodes = 30;
    const SteklovPoincare S(P, mo);
    const DenseSchur d = dense_schur(P);
    const index n = S.size();
    Eigen::MatrixXd Smf(n, n);
    std::vector<real> e(n), col(n);
    for (index j = 0; j < n; ++j) {
      std::fill(e.begin(), e.end(), 0.0);
      e[j] = 1;
      ASSERT_TRUE(S.apply(e.data(), col.data(), 1e-13).ok());
      for (index i = 0; i < n; ++i) Smf(i, j) = col[i];
    }
    const real scale = d.S.cwiseAbs().maxCoeff();
    EXPECT_LT((Smf - d.S).cwiseAbs().maxCoeff(), 1e-9 * scale);
    EXPECT_LT((Smf - Smf.transpose()).cwiseAbs().maxCoeff(), 1e-9 * scale);
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (Smf + Smf.transpose()));
    EXPECT_GT(es.eigenvalues().minCoeff(), 1e-6 * scale);
    Field<real> b;
    ASSERT_TRUE(S.condensed_load(1e-13, b).ok());
    real berr = 0;
    for (index i = 0; i < n; ++i) berr = std::max(berr, std::abs(b[i] - d.b[i]));
    EXPECT_LT(berr, 1e-9 * d.b.cwiseAbs().maxCoeff());
  }
}

TEST(SteklovPoincare, RecoveryAndResidualMatchDense) {
  const Problem P = make_problem(spec_for_dims(5, 3, 2));
  SteklovPoincare S(P);
  const DenseSchur d = dense_schur(P);
  auto uc = test::random_vector(S.size(), 4);
  for (auto& v : uc) v *= 1e-3;
  // u = E u_c + K_ii^{-1} l_i: the extension from an S apply, the interior
  // load solution from the condensed load
  std::vector<real> u(3 * P.nodes()), Sv(S.size());
  Field<real> b, li;
  ASSERT_TRUE(S.apply(uc.data(), Sv.data(), 1e-13, u.data()).ok());
  ASSERT_TRUE(S.condensed_load(1e-13, b, &li).ok());
  for (size_t i = 0; i < u.size(); ++i) u[i] += li[i];
  expect_dense_body(d, uc, u);
  // the same body and r = S u - b̃ from one solve (SteklovPoincare::residual)
  std::vector<real> r(S.size()), body(S.full_size());
  ASSERT_TRUE(S.residual(uc.data(), r.data(), 1e-13, body.data()).ok());
  expect_dense_body(d, uc, body);
  Eigen::Map<const Eigen::VectorXd> ucv(uc.data(), S.size());
  const Eigen::VectorXd rd = d.S * ucv - d.b;
  real rerr = 0;
  for (index i = 0; i < S.size(); ++i) rerr = std::max(rerr, std::abs(r[i] - rd[i]));
  EXPECT_LT(rerr, 1e-9 * rd.cwiseAbs().maxCoeff());
}

// b̃ without a solve, l_c − K_ci z, from a given z: K_ii^{-1} l_i itself
// gives the condensed load (the dense one), whatever z holds on the
// constrained planes or beyond the plane next to the contact face
TEST(SteklovPoincare, CondensedLoadFromTheInteriorSolutionIsTheCondensedLoad) {
  const Problem P = make_problem(spec_for_dims(5, 3, 4));
  const SteklovPoincare S(P);
  const DenseSchur d = dense_schur(P);
  Field<real> b, li;
  ASSERT_TRUE(S.condensed_load(1e-13, b, &li).ok());
  const real scale = d.b.cwiseAbs().maxCoeff();
  Field<real> from;
  std::vector<real> z = li.to_vector();
  S.condensed_load_from(z.data(), from);
  ASSERT_EQ(index(from.size()), S.size());
  for (index i = 0; i < S.size(); ++i) {
    EXPECT_NEAR(from[i], d.b[i], 1e-9 * scale) << i;
    EXPECT_NEAR(from[i], b[i], 1e-13 * scale) << i;
  }
  // garbage on the contact face (zeroed) and on the planes iz >= 2 (not read)
  const GridDims& g = P.grid;
  const index N = g.nodes(), plane = g.nx() * g.ny();
  for (int a = 0; a < 3; ++a)
    for (index k = 0; k < N; ++k)
      if (k < plane || k >= 2 * plane) z[a * N + k] = 1e3 * real(k % 7 + 1);
  Field<real> again;
  S.condensed_load_from(z.data(), again);
  for (index i = 0; i < S.size(); ++i) EXPECT_EQ(again[i], from[i]) << i;
}

TEST(SteklovPoincare, ResidualFromAWarmBodyOnlyCorrects) {
  // a body off by 1e-6 relative: the same residual in fewer iterations
  const Problem P = make_problem(spec_for_dims(16, 8, 8));
  SteklovPoincare S(P);
  auto uc = test::random_vector(S.size(), 7);
  for (auto& v : uc) v *= 1e-3;
  std::vector<real> r(S.size()), body(S.full_size());
  const SolveStats cold = S.residual(uc.data(), r.data(), 1e-12, body.data());
  ASSERT_TRUE(cold.ok());
  std::vector<real> warm(body), r2(S.size());
  const auto noise = test::random_vector(S.full_size(), 8);
  const real umax = test::max_abs(body);
  for (size_t i = 0; i < warm.size(); ++i) warm[i] += 1e-6 * umax * noise[i];
  const SolveStats w = S.residual(uc.data(), r2.data(), 1e-12, warm.data(), warm.data());
  ASSERT_TRUE(w.ok());
  EXPECT_LT(w.iterations, cold.iterations - 2);
  EXPECT_LT(test::max_abs_diff(r2, r), 1e-9 * test::max_abs(r));
}

// S v and E v however the caller asks (the inner solve runs in the
// extension itself where one is given, from a guess in place where the
// guess is that array): without an extension, with one, with a guess apart
// (left as it was) and with the guess in the extension: the same S v
TEST(SteklovPoincare, ExtensionAskedForInPlaceOrApartGivesTheSameApply) {
  const Problem P = make_problem(spec_for_dims(12, 6, 5));
  SteklovPoincare S(P);
  auto v = test::random_vector(S.size(), 9);
  for (auto& e : v) e *= 1e-3;
  const index n = S.size(), nf = S.full_size();
  std::vector<real> Sv0(n), Sv1(n), Sv2(n), Sv3(n), E1(nf, std::nan("")), E2(nf), E3(nf);
  ASSERT_TRUE(S.apply(v.data(), Sv0.data(), 1e-12).ok());
  ASSERT_TRUE(S.apply(v.data(), Sv1.data(), 1e-12, E1.data()).ok());
  for (index i = 0; i < n; ++i) ASSERT_EQ(Sv0[i], Sv1[i]) << i;  // (the same solve, in another array)
  // a guess near E v, apart from the extension and in it
  auto guess = E1;
  const auto noise = test::random_vector(nf, 10);
  for (index i = 0; i < nf; ++i) guess[i] += 1e-7 * test::max_abs(E1) * noise[i];
  const auto guess_was = guess;
  ASSERT_TRUE(S.apply(v.data(), Sv2.data(), 1e-12, E2.data(), guess.data()).ok());
  for (index i = 0; i < nf; ++i) ASSERT_EQ(guess[i], guess_was[i]) << i;
  E3 = guess;
  ASSERT_TRUE(S.apply(v.data(), Sv3.data(), 1e-12, E3.data(), E3.data()).ok());
  for (index i = 0; i < n; ++i) ASSERT_EQ(Sv2[i], Sv3[i]) << i;
  for (index i = 0; i < nf; ++i) ASSERT_EQ(E2[i], E3[i]) << i;
  EXPECT_LT(test::max_abs_diff(Sv2, Sv0), 1e-9 * test::max_abs(Sv0));
  EXPECT_LT(test::max_abs_diff(E2, E1), 1e-9 * test::max_abs(E1));
}

}  // namespace tresca
