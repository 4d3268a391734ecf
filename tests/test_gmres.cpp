// GMRES on non-symmetric operators against a dense LU solve, on the SPD
// elasticity system with the multigrid preconditioner (against CG), and its
// failure reasons.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>

#include "core/fem/problem.hpp"
#include "core/solvers/gmres.hpp"
#include "core/multigrid/multigrid.hpp"
#include "kernels/vector_ops.hpp"
#include "test_helpers.hpp"

namespace tresca {

namespace {
class DenseOperator : public LinearOperator {
 public:
  explicit DenseOperator(Eigen::MatrixXd A) : A_(std::move(A)) {}
  index size() const override { return A_.rows(); }
  void apply(const real* x, real* y) const override {
    Eigen::Map<Eigen::VectorXd>(y, size()) = A_ * Eigen::Map<const Eigen::VectorXd>(x, size());
  }
  const Eigen::MatrixXd& matrix() const { return A_; }

 private:
  Eigen::MatrixXd A_;
};

// 1D convection-diffusion, upwind: strongly non-symmetric for large Peclet numbers
Eigen::MatrixXd convection_diffusion(index n, real peclet) {
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  for (index i = 0; i < n; ++i) {
    A(i, i) = 2 + peclet;
    if (i > 0) A(i, i - 1) = -1 - peclet;
    if (i + 1 < n) A(i, i + 1) = -1;
  }
  return A;
}

class Jacobi : public LinearOperator {
 public:
  explicit Jacobi(const Eigen::MatrixXd& A) : d_(A.diagonal().cwiseInverse()) {}
  index size() const override { return d_.size(); }
  void apply(const real* x, real* y) const override {
    for (index i = 0; i < size(); ++i) y[i] = d_[i] * x[i];
  }

 private:
  Eigen::VectorXd d_;
};
}  // namespace

TEST(GMRES, SolvesNonSymmetricSystemsLikeDenseLU) {
  for (real peclet : {0.0, 1.0, 50.0}) {
    const DenseOperator A(convection_diffusion(197, peclet));
    const Jacobi M(A.matrix());
    const auto b = test::random_vector(A.size(), 3);
    const Eigen::VectorXd xref = A.matrix().partialPivLu().solve(Eigen::Map<const Eigen::VectorXd>(b.data(), A.size()));
    for (int restart : {10, 200}) {
      for (const LinearOperator* pc : {static_cast<const LinearOperator*>(nullptr), static_cast<const LinearOperator*>(&M)}) {
        std::vector<real> x(A.size());
        GMRESOptions o;
        o.rtol = 1e-12;
        o.restart = restart;
        o.max_iterations = 20000;
        const SolveStats st = gmres(A, pc, b.data(), x.data(), o);
        ASSERT_TRUE(st.ok()) << to_string(st.reason) << " Pe " << peclet << " m " << restart;
        real err = 0;
        for (index i = 0; i < A.size(); ++i) err = std::max(err, std::abs(x[i] - xref[i]));
        EXPECT_LT(err, 1e-8 * xref.cwiseAbs().maxCoeff()) << "Pe " << peclet << " m " << restart;
        // the reported residual is the true one
        std::vector<real> r(A.size());
        A.apply(x.data(), r.data());
        for (index i = 0; i < A.size(); ++i) r[i] = b[i] - r[i];
        EXPECT_LE(norm2(A.size(), r.data()), 1.01e-12 * norm2(A.size(), b.data()) + 1e-300);
      }
    }
  }
}

TEST(GMRES, MatchesCGOnTheElasticitySystemWithMultigrid) {
  const Problem P = make_problem(spec_for_level(5));
  Multigrid mg(P.grid, P.interior_faces, P.spec.E, P.spec.nu);
  const Field<real> load = whole_load(P);
  std::vector<real> b(load.begin(), load.end());
  zero_constrained(P.grid, P.interior_faces, b.data());
  std::vector<real> xg(P.dofs()), xc(P.dofs());
  GMRESOptions go;
  go.rtol = 1e-10;
  const SolveStats sg = gmres(mg.op(0), &mg, b.data(), xg.data(), go);
  CGOptions co;
  co.rtol = 1e-10;
  CGWorkspace ws;
  const SolveStats sc = pcg(mg.op(0), &mg, b.data(), xc.data(), co, ws);
  ASSERT_TRUE(sg.ok() && sc.ok());
  EXPECT_LE(sg.iterations, sc.iterations + 3);
  EXPECT_LT(test::max_abs_diff(xg, xc), 1e-8 * test::max_abs(xc));
}

TEST(GMRES, ReportsWhyItStopped) {
  const DenseOperator A(convection_diffusion(100, 10.0));
  auto b = test::random_vector(A.size(), 5);
  std::vector<real> x(A.size());
  GMRESOptions o;
  o.max_iterations = 5;
  EXPECT_EQ(gmres(A, nullptr, b.data(), x.data(), o).reason, SolveReason::max_iterations);
  b[7] = NAN;
  EXPECT_EQ(gmres(A, nullptr, b.data(), x.data(), GMRESOptions{}).reason, SolveReason::non_finite);
  // singular A: the Krylov space closes without solving
  Eigen::MatrixXd S = Eigen::MatrixXd::Identity(10, 10);
  S(9, 9) = 0;
  const DenseOperator As(S);
  std::vector<real> bs(10, 1.0), xs(10);
  EXPECT_EQ(gmres(As, nullptr, bs.data(), xs.data(), GMRESOptions{}).reason, SolveReason::breakdown);
  // and bad arguments are refused
  GMRESOptions bad;
  bad.restart = 0;
  EXPECT_THROW(gmres(A, nullptr, b.data(), x.data(), bad), std::invalid_argument);
}

}  // namespace tresca
