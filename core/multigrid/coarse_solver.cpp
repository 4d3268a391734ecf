#include "core/multigrid/coarse_solver.hpp"

#include <Eigen/OrderingMethods>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <mutex>
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

// K with F ordered last and I by AMD, factorised, and K's Schur complement
// on F; with the K and F it was made from, to be shared (the header)
struct CoarseSolver::FaceLastFactor {
  SparseMatrix K;                // as given (its lower triangle read)
  std::vector<index> face;       // as given
  std::vector<index> position;   // dof i's place in P K P^T
  std::vector<index> order;      // its inverse: the dof at place k
  index interior = 0;            // |I|: F is places [interior, n)
  Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower, Eigen::NaturalOrdering<index>> face_last;
  Eigen::MatrixXd S;

  FaceLastFactor(const SparseMatrix& K_, const std::vector<index>& face_, std::vector<index> position_);
  bool made_from(const SparseMatrix& A, const std::vector<index>& f) const {
    auto same = [](const auto* a, const auto* b, Eigen::Index n) { return std::memcmp(a, b, sizeof(*a) * n) == 0; };
    return f == face && A.rows() == K.rows() && A.nonZeros() == K.nonZeros() && A.isCompressed() && K.isCompressed() &&
           same(A.outerIndexPtr(), K.outerIndexPtr(), K.outerSize() + 1) &&
           same(A.innerIndexPtr(), K.innerIndexPtr(), K.nonZeros()) && same(A.valuePtr(), K.valuePtr(), K.nonZeros());
  }
};

CoarseSolver::FaceLastFactor::FaceLastFactor(const SparseMatrix& K_, const std::vector<index>& face_,
                                             std::vector<index> position_)
    : K(K_), face(face_), position(std::move(position_)) {
  const index n = index(K.rows()), nF = index(face.size());
  interior = n - nF;
  // I in the AMD order of K_II (taken from K with I first, in natural order)
  std::vector<index> inner;
  inner.reserve(std::size_t(interior));
  for (index i = 0; i < n; ++i)
    if (position[std::size_t(i)] < 0) inner.push_back(i);
  Permutation P(n);  // P.indices()[i]: dof i's place (P A P^T, Eigen's twistedBy)
  for (index i = 0; i < n; ++i) P.indices()[i] = position[std::size_t(i)];
  for (index k = 0; k < interior; ++k) P.indices()[inner[std::size_t(k)]] = k;
  SparseMatrix split(n, n);
  split.selfadjointView<Eigen::Lower>() = K.selfadjointView<Eigen::Lower>().twistedBy(P);
  const SparseMatrix K_II = split.topLeftCorner(interior, interior);
  Permutation amd;  // amd.indices()[k]: the dof of K_II eliminated k-th
  Eigen::AMDOrdering<index>()(K_II.selfadjointView<Eigen::Lower>(), amd);
  for (index k = 0; k < interior; ++k) position[std::size_t(inner[std::size_t(amd.indices()[k])])] = k;
  order.assign(std::size_t(n), 0);
  for (index i = 0; i < n; ++i) {
    P.indices()[i] = position[std::size_t(i)];
    order[std::size_t(position[std::size_t(i)])] = i;
  }
  SparseMatrix PKPt(n, n);
  PKPt.selfadjointView<Eigen::Lower>() = K.selfadjointView<Eigen::Lower>().twistedBy(P);
  face_last.compute(PKPt);
  if (face_last.info() != Eigen::Success || !pivots_ok(face_last.vectorD()))
    throw std::runtime_error("coarse solver: the factorisation of K met a zero or non-finite pivot");
  // S = L_FF D_F L_FF^T from the factor's trailing columns (L's unit
  // diagonal is not stored)
  const SparseMatrix& L = face_last.matrixL().nestedExpression();
  Eigen::MatrixXd L_FF = Eigen::MatrixXd::Identity(nF, nF);
  for (index j = interior; j < n; ++j)
    for (SparseMatrix::InnerIterator it(L, j); it; ++it)
      if (it.row() > j) L_FF(it.row() - interior, j - interior) = it.value();
  S = L_FF * face_last.vectorD().tail(nF).asDiagonal() * L_FF.transpose();
}

namespace {
// the most recent factors, newest last (the header: shared between solvers)
struct RecentFactors {
  static constexpr std::size_t kKept = 4;
  std::mutex mutex;
  std::vector<std::shared_ptr<const CoarseSolver::FaceLastFactor>> kept;
  CoarseSolver::Shared count;
};
RecentFactors& recent_factors() {
  static RecentFactors* r = new RecentFactors;  // (never destroyed: solvers may outlive statics)
  return *r;
}
}  // namespace

CoarseSolver::Shared CoarseSolver::shared_factors() {
  RecentFactors& r = recent_factors();
  std::lock_guard<std::mutex> lock(r.mutex);
  return r.count;
}

void CoarseSolver::factor(const SparseMatrix& K, const std::vector<index>& face) {
  const index n = index(K.rows()), nF = index(face.size());
  if (K.cols() != n) throw std::invalid_argument("coarse solver: the matrix is not square");
  std::vector<index> position(std::size_t(n), -1);  // F last, as given; I's places below
  for (index k = 0; k < nF; ++k) {
    const index i = face[std::size_t(k)];
    if (i < 0 || i >= n || position[std::size_t(i)] >= 0)
      throw std::invalid_argument("coarse solver: face dof " + std::to_string(i) + " out of range or repeated");
    position[std::size_t(i)] = n - nF + k;
  }
  n_ = n;
  dense_face_ = nF <= max_dense_face_;
  K_ = SparseMatrix();
  factor_.reset();
  outer_.clear();  // (the sparse path orders K + B afresh)
  if (!dense_face_) {
    K_ = K;
    update(SparseMatrix(n, n));
    return;
  }
  RecentFactors& r = recent_factors();
  {
    std::lock_guard<std::mutex> lock(r.mutex);
    for (const auto& f : r.kept)
      if (f->made_from(K, face)) {
        factor_ = f;
        r.count.reused += 1;
        break;
      }
  }
  if (!factor_) {
    auto made = std::make_shared<const FaceLastFactor>(K, face, std::move(position));
    std::lock_guard<std::mutex> lock(r.mutex);
    r.count.made += 1;
    if (r.kept.size() == RecentFactors::kKept) r.kept.erase(r.kept.begin());
    r.kept.push_back(made);
    factor_ = std::move(made);
  }
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
  const FaceLastFactor& f = *factor_;
  Eigen::MatrixXd SB = f.S;
  for (index j = 0; j < n; ++j)
    for (SparseMatrix::InnerIterator it(B, j); it; ++it) {
      if (it.value() == 0) continue;
      const index pi = f.position[std::size_t(it.row())] - f.interior, pj = f.position[std::size_t(j)] - f.interior;
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
  const index n = size();
  if (b.size() != n) throw std::invalid_argument("coarse solver: right-hand side of the wrong size");
  if (!dense_face_) {
    x = whole_.solve(b);
    return;
  }
  // the factor's sweeps over I's columns (column by column through L,
  // whose unit diagonal is not stored), F's dense solve between them
  const FaceLastFactor& f = *factor_;
  const index interior = f.interior, nF = n - interior;
  const std::vector<index>& order = f.order;
  const SparseMatrix& L = f.face_last.matrixL().nestedExpression();
  const Eigen::VectorXd& D = f.face_last.vectorD();
  v_.resize(n);
  for (index k = 0; k < n; ++k) v_[k] = b[order[std::size_t(k)]];
  for (index j = 0; j < interior; ++j)  // v_I = y_I = L_II^-1 b_I, v_F = b_F - L_FI y_I
    for (SparseMatrix::InnerIterator it(L, j); it; ++it)
      if (it.row() > j) v_[it.row()] -= it.value() * v_[j];
  if (nF > 0) v_.tail(nF) = face_.solve(v_.tail(nF));  // x_F
  for (index j = interior - 1; j >= 0; --j) {  // x_I = L_II^-T (D_I^-1 y_I - L_FI^T x_F)
    real xj = v_[j] / D[j];
    for (SparseMatrix::InnerIterator it(L, j); it; ++it)
      if (it.row() > j) xj -= it.value() * v_[it.row()];
    v_[j] = xj;
  }
  x.resize(n);
  for (index k = 0; k < n; ++k) x[order[std::size_t(k)]] = v_[k];
}

}  // namespace tresca
