// The coarsest multigrid level's direct solve of (K + B) x = b, where K, the
// assembled stiffness, is fixed for the multigrid's life, and B, the bottom
// block's projection, changes at every Newton step but lives on a fixed set
// F of dofs (the bottom plane's).
//
// K is factorised once (sparse LDLT, Eigen), with F ordered last and the
// other dofs I by AMD:
//
//   P K P^T = L D L^T,   L = [L_II 0; L_FI L_FF],
//
// so that K's Schur complement on F is the factor's trailing block,
// S = K_FF - K_FI K_II^-1 K_IF = L_FF D_F L_FF^T (dense, |F| x |F|), and
// K + B's is S + B_FF. A new B is then a dense LDLT of |F| x |F| (120 of
// the 675 dofs on the coarsest grid of level 8's hierarchy), not an
// assembly and a sparse refactorisation of the whole (RESULTS.md §0zk:
// about 3 ms each, once a Newton step, on one thread). A solve is the
// factor's sweeps over I's columns with F's dense solve between them:
//
//   y_I = L_II^-1 (P b)_I;   x_F = (S + B_FF)^-1 ((P b)_F - L_FI y_I);
//   (P x)_I = L_II^-T (D_I^-1 y_I - L_FI^T x_F).
//
// Where F is large (a coarsest grid one element thick has half its dofs in
// the bottom plane), the dense block would cost more than the sparse
// refactorisation: with |F| > max_dense_face, a new B refactorises K + B
// (AMD ordering, kept while the pattern stays) instead. Either way the
// answer is (K + B)^-1 b to rounding.
//
// The factor of K (its ordering, L, D and S) is shared: solvers given the
// same K and F, bit for bit, use one factor. Nested iteration makes two
// multigrids on every mesh (the interior solves' and the Newton step's
// preconditioner's), and at level 8 all three meshes end on the same
// coarsest grid: 2 factorisations instead of 6 (RESULTS.md §0zl).
// The few most recent factors are kept for the next solver (a coarser
// mesh's multigrids are gone before the finer mesh's are made).
#pragma once
#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <memory>
#include <vector>

#include "core/fem/assembly.hpp"

namespace tresca {

class CoarseSolver {
 public:
  static constexpr index kMaxDenseFace = 256;  // (measured: RESULTS.md §0zk)
  explicit CoarseSolver(index max_dense_face = kMaxDenseFace) : max_dense_face_(max_dense_face) {}

  // K symmetric positive definite (its lower triangle is read); face: the
  // dofs a B of update() may touch, each once. Solves with K until update().
  // Throws std::runtime_error where a pivot is zero or not finite.
  void factor(const SparseMatrix& K, const std::vector<index>& face);
  // B (n x n, symmetric, nonzero on face x face only) replaces the last;
  // an empty (all-zero) B leaves K
  void update(const SparseMatrix& B);
  // x = (K + B)^-1 b (x may not alias b)
  void solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) const;

  index size() const { return n_; }
  // whether F's Schur complement is kept dense (|F| <= max_dense_face)
  bool dense_face() const { return dense_face_; }
  // factorisations of K this process made (dense-face path), and those a
  // solver took from another of the same K and F instead
  struct Shared {
    long long made = 0, reused = 0;
  };
  static Shared shared_factors();

  // the dense-face path's factor of K, shared (above)
  struct FaceLastFactor;

 private:
  index max_dense_face_;
  bool dense_face_ = false;
  index n_ = 0;
  SparseMatrix K_;  // (the sparse path's: K + B is refactorised from it)
  // the dense-face path: P K P^T's factor and S (shared), S + B's factor
  std::shared_ptr<const FaceLastFactor> factor_;
  Eigen::LDLT<Eigen::MatrixXd> face_;
  // the sparse path's factor of K + B, and the pattern its ordering is for
  Eigen::SimplicialLDLT<SparseMatrix> whole_;
  std::vector<index> outer_, inner_;
  mutable Eigen::VectorXd v_;
};

}  // namespace tresca
