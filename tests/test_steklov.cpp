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
    std::vector<real> b;
    ASSERT_TRUE(S.condensed_load(1e-13, b).ok());
    real berr = 0;
    for (index i = 0; i < n; ++i) berr = std::max(berr, std::abs(b[i] - d.b[i]));
    EXPECT_LT(berr, 1e-9 * d.b.cwiseAbs().maxCoeff());
  }
}

TEST(SteklovPoincare, RecoveryMatchesDenseInteriorSolve) {
  const Problem P = make_problem(spec_for_dims(5, 3, 2));
  SteklovPoincare S(P);
  const DenseSchur d = dense_schur(P);
  auto uc = test::random_vector(S.size(), 4);
  for (auto& v : uc) v *= 1e-3;
  // u = E u_c + K_ii^{-1} l_i: the extension from an S apply, the interior
  // load solution from the condensed load
  std::vector<real> u(3 * P.nodes()), li, b, Sv(S.size());
  ASSERT_TRUE(S.apply(uc.data(), Sv.data(), 1e-13, u.data()).ok());
  ASSERT_TRUE(S.condensed_load(1e-13, b, &li).ok());
  for (size_t i = 0; i < u.size(); ++i) u[i] += li[i];
  Eigen::Map<const Eigen::VectorXd> ucv(uc.data(), S.size());
  const Eigen::VectorXd ui = Eigen::LDLT<Eigen::MatrixXd>(d.Kii).solve(d.li - d.Kic * ucv);
  real err = 0;
  for (size_t r = 0; r < d.idof.size(); ++r) err = std::max(err, std::abs(u[d.idof[r]] - ui[r]));
  EXPECT_LT(err, 1e-9 * ui.cwiseAbs().maxCoeff());
  for (size_t r = 0; r < d.cdof.size(); ++r) EXPECT_EQ(u[d.cdof[r]], uc[r]);
}

}  // namespace tresca
