#include "core/multigrid/coarse_solver.hpp"

#include <Eigen/OrderingMethods>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace tresca {

namespace {
using Permutation = Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, index>;

bool pivots_ok(const Eigen::VectorXd& d) {
  for (Eigen::Index i = 0; i < d.size(); ++i)
    if (!std::isfinite(d[i]) || d[i] == 0) return false;
  return true;
}
}  // namespace

void CoarseSolver::factor(const SparseMatrix& K, const std::vector<index>& face) {
  const index n = index(K.rows()), nF = index(face.size());
  if (K.cols() != n) throw std::invalid_argument("coarse solver: the matrix is not square");
  interior_ = n - nF;
  position_.assign(std::size_t(n), -1);  // F last, as given; I's places below
  for (index k = 0; k < nF; ++k) {
    const index i = face[std::size_t(k)];
    if (i < 0 || i >= n || position_[std::size_t(i)] >= 0)
      throw std::invalid_argument("coarse solver: face dof " + std::to_string(i) + " out of range or repeated");
    position_[std::size_t(i)] = interior_ + k;
  }
  dense_face_ = nF <= max_dense_face_;
  K_ = SparseMatrix();
  outer_.clear();  // (the sparse path orders K + B afresh)
  if (!dense_face_) {
    K_ = K;
    update(SparseMatrix(n, n));
    return;
  }
  // I in the AMD order of K_II (taken from K with I first, in natural order)
  std::vector<index> interior;
  interior.reserve(std::size_t(interior_));
  for (index i = 0; i < n; ++i)
    if (position_[std::size_t(i)] < 0) interior.push_back(i);
  Permutation P(n);  // P.indices()[i]: dof i's place (P A P^T, Eigen's twistedBy)
  for (index i = 0; i < n; ++i) P.indices()[i] = position_[std::size_t(i)];
  for (index k = 0; k < interior_; ++k) P.indices()[interior[std::size_t(k)]] = k;
  SparseMatrix split(n, n);
  split.selfadjointView<Eigen::Lower>() = K.selfadjointView<Eigen::Lower>().twistedBy(P);
  const SparseMatrix K_II = split.topLeftCorner(interior_, interior_);
  Permutation amd;  // amd.indices()[k]: the dof of K_II eliminated k-th
  Eigen::AMDOrdering<index>()(K_II.selfadjointView<Eigen::Lower>(), amd);
  for (index k = 0; k < interior_; ++k) position_[std::size_t(interior[std::size_t(amd.indices()[k])])] = k;
  order_.assign(std::size_t(n), 0);
  for (index i = 0; i < n; ++i) {
    P.indices()[i] = position_[std::size_t(i)];
    order_[std::size_t(position_[std::size_t(i)])] = i;
  }
  SparseMatrix PKPt(n, n);
  PKPt.selfadjointView<Eigen::Lower>() = K.selfadjointView<Eigen::Lower>().twistedBy(P);
  face_last_.compute(PKPt);
  if (face_last_.info() != Eigen::Success || !pivots_ok(face_last_.vectorD()))
    throw std::runtime_error("coarse solver: the factorisation of K met a zero or non-finite pivot");
  // S = L_FF D_F L_FF^T from the factor's trailing columns (L's unit
  // diagonal is not stored)
  const SparseMatrix& L = face_last_.matrixL().nestedExpression();
  Eigen::MatrixXd L_FF = Eigen::MatrixXd::Identity(nF, nF);
  for (index j = interior_; j < n; ++j)
    for (SparseMatrix::InnerIterator it(L, j); it; ++it)
      if (it.row() > j) L_FF(it.row() - interior_, j - interior_) = it.value();
  S_ = L_FF * face_last_.vectorD().tail(nF).asDiagonal() * L_FF.transpose();
  update(SparseMatrix(n, n));
}

void CoarseSolver::update(const SparseMatrix& B) {
  const index n = size();
  if (B.rows() != n || B.cols() != n)
    throw std::invalid_argument("coarse solver: B is " + std::to_string(B.rows()) + " x " + std::to_string(B.cols()) +
                                ", the matrix " + std::to_string(n) + " x " + std::to_string(n));
  if (!dense_face_) {
    SparseMatrix A = K_ + B;
    A.prune(0.0);
    A.makeCompressed();
    const std::size_t cols = std::size_t(n) + 1, nnz = std::size_t(A.nonZeros());
    const bool same = outer_.size() == cols && inner_.size() == nnz &&
                      std::equal(A.outerIndexPtr(), A.outerIndexPtr() + cols, outer_.begin()) &&
                      std::equal(A.innerIndexPtr(), A.innerIndexPtr() + nnz, inner_.begin());
    if (!same) {  // the ordering (AMD) and the symbolic factorisation, once per pattern
      whole_.analyzePattern(A);
      outer_.assign(A.outerIndexPtr(), A.outerIndexPtr() + cols);
      inner_.assign(A.innerIndexPtr(), A.innerIndexPtr() + nnz);
    }
    whole_.factorize(A);
    if (whole_.info() != Eigen::Success || !pivots_ok(whole_.vectorD())) {
      outer_.clear();  // (ordered afresh next time)
      throw std::runtime_error("coarse solver: the factorisation of K + B met a zero or non-finite pivot");
    }
    return;
  }
  Eigen::MatrixXd SB = S_;
  for (index j = 0; j < n; ++j)
    for (SparseMatrix::InnerIterator it(B, j); it; ++it) {
      if (it.value() == 0) continue;
      const index pi = position_[std::size_t(it.row())] - interior_, pj = position_[std::size_t(j)] - interior_;
      if (pi < 0 || pj < 0)
        throw std::invalid_argument("coarse solver: B has an entry at (" + std::to_string(it.row()) + ", " +
                                    std::to_string(j) + "), off the face it was factorised for");
      SB(pi, pj) += it.value();
    }
  if (SB.rows() == 0) return;  // (no face: K alone)
  face_.compute(SB);
  if (face_.info() != Eigen::Success || !pivots_ok(face_.vectorD()))
    throw std::runtime_error("coarse solver: the face block of K + B met a zero or non-finite pivot");
}

void CoarseSolver::solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) const {
  const index n = size(), nF = n - interior_;
  if (b.size() != n) throw std::invalid_argument("coarse solver: right-hand side of the wrong size");
  if (!dense_face_) {
    x = whole_.solve(b);
    return;
  }
  // the factor's sweeps over I's columns (column by column through L,
  // whose unit diagonal is not stored), F's dense solve between them
  const SparseMatrix& L = face_last_.matrixL().nestedExpression();
  const Eigen::VectorXd& D = face_last_.vectorD();
  v_.resize(n);
  for (index k = 0; k < n; ++k) v_[k] = b[order_[std::size_t(k)]];
  for (index j = 0; j < interior_; ++j)  // v_I = y_I = L_II^-1 b_I, v_F = b_F - L_FI y_I
    for (SparseMatrix::InnerIterator it(L, j); it; ++it)
      if (it.row() > j) v_[it.row()] -= it.value() * v_[j];
  if (nF > 0) v_.tail(nF) = face_.solve(v_.tail(nF));  // x_F
  for (index j = interior_ - 1; j >= 0; --j) {  // x_I = L_II^-T (D_I^-1 y_I - L_FI^T x_F)
    real xj = v_[j] / D[j];
    for (SparseMatrix::InnerIterator it(L, j); it; ++it)
      if (it.row() > j) xj -= it.value() * v_[it.row()];
    v_[j] = xj;
  }
  x.resize(n);
  for (index k = 0; k < n; ++k) x[order_[std::size_t(k)]] = v_[k];
}

}  // namespace tresca
