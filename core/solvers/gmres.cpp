#include "core/solvers/gmres.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "kernels/launch.hpp"
#include "kernels/vector_ops.hpp"

namespace tresca {

SolveStats gmres(const LinearOperator& A, const LinearOperator* M, const real* b, real* x, const GMRESOptions& opt) {
  const index n = A.size();
  if (M && M->size() != n)
    throw std::invalid_argument("gmres: preconditioner size " + std::to_string(M->size()) + " differs from operator size " +
                                std::to_string(n));
  if (opt.restart < 1 || opt.max_iterations < 0 || !(opt.rtol >= 0) || !(opt.atol >= 0))
    throw std::invalid_argument("gmres: restart must be >= 1, tolerances and max_iterations >= 0");
  const int m = opt.restart;
  std::vector<Field<real>> V(m + 1, Field<real>(n)), Z(m, Field<real>(n));
  std::vector<real> H((m + 1) * m), cs(m), sn(m), g(m + 1), y(m);
  Field<real> w(n);
  auto h = [&](int i, int j) -> real& { return H[i * m + j]; };

  SolveStats st;
  // local sums -> over all ranks (identity on one rank)
  auto norm = [&](const real* v) { return std::sqrt(opt.reduction ? opt.reduction->sum(dot(n, v, v)) : dot(n, v, v)); };
  st.rhs_norm = norm(b);
  const real target = std::max(opt.rtol * st.rhs_norm, opt.atol);
  if (opt.zero_initial_guess) fill<real>(n, 0, x);
  bool first = true;
  for (;;) {
    // r = b − A x, recomputed at every (re)start
    real* r = V[0].data();
    if (first && opt.zero_initial_guess) {
      copy(n, b, r);
    } else {
      A.update_ghosts(x);
      A.apply(x, w.data());
      st.operator_applications += 1;
      copy(n, b, r);
      axpy(n, -1, w.data(), r);
    }
    const real beta = norm(r);
    if (first) st.initial_residual = beta;
    first = false;
    st.residual = beta;
    if (!std::isfinite(beta)) {
      st.reason = SolveReason::non_finite;
      return st;
    }
    if (beta <= target) return st;
    if (st.iterations >= opt.max_iterations) {
      st.reason = SolveReason::max_iterations;
      return st;
    }
    scale(n, 1 / beta, r);
    std::fill(g.begin(), g.end(), 0.0);
    g[0] = beta;
    int j = 0;
    bool invariant = false;
    for (; j < m && st.iterations < opt.max_iterations; ++j) {
      // w = A M v_j (flexible: z_j kept)
      if (M) {
        M->apply(V[j].data(), Z[j].data());
        st.preconditioner_applications += 1;
      } else {
        copy(n, V[j].data(), Z[j].data());
      }
      A.update_ghosts(Z[j].data());
      A.apply(Z[j].data(), w.data());
      st.operator_applications += 1;
      st.iterations += 1;
      if (opt.abort_if && opt.abort_if()) {
        st.reason = SolveReason::aborted;
        return st;
      }
      for (int i = 0; i <= j; ++i) {
        h(i, j) = dot(n, w.data(), V[i].data());
        if (opt.reduction) h(i, j) = opt.reduction->sum(h(i, j));
        axpy(n, -h(i, j), V[i].data(), w.data());
      }
      const real hn = norm(w.data());  // ||w||: the next basis vector is w / hn
      h(j + 1, j) = hn;
      if (!std::isfinite(hn)) {
        st.reason = SolveReason::non_finite;
        return st;
      }
      // apply the previous rotations to the new column, then make a new one
      for (int i = 0; i < j; ++i) {
        const real t = cs[i] * h(i, j) + sn[i] * h(i + 1, j);
        h(i + 1, j) = -sn[i] * h(i, j) + cs[i] * h(i + 1, j);
        h(i, j) = t;
      }
      const real den = std::hypot(h(j, j), h(j + 1, j));
      invariant = hn <= 1e-14 * den;  // the Krylov space is invariant
      cs[j] = den > 0 ? h(j, j) / den : 1;
      sn[j] = den > 0 ? h(j + 1, j) / den : 0;
      h(j, j) = den;
      h(j + 1, j) = 0;
      g[j + 1] = -sn[j] * g[j];
      g[j] = cs[j] * g[j];
      st.residual = std::abs(g[j + 1]);  // the least-squares residual = ||r|| in exact arithmetic
      if (!invariant) {
        copy(n, w.data(), V[j + 1].data());
        scale(n, 1 / hn, V[j + 1].data());
      }
      if (st.residual <= target || invariant) {
        ++j;
        break;
      }
    }
    // x += Z y with H y = g (upper triangular, j columns)
    for (int i = j - 1; i >= 0; --i) {
      real s = g[i];
      for (int k = i + 1; k < j; ++k) s -= h(i, k) * y[k];
      if (h(i, i) == 0) {
        st.reason = SolveReason::breakdown;
        return st;
      }
      y[i] = s / h(i, i);
    }
    for (int i = 0; i < j; ++i) axpy(n, y[i], Z[i].data(), x);
    if (invariant && st.residual > target) {
      // the space is exhausted: the recomputed residual decides
      A.update_ghosts(x);
      A.apply(x, w.data());
      st.operator_applications += 1;
      copy(n, b, r);
      axpy(n, -1, w.data(), r);
      st.residual = norm(r);
      if (st.residual > target) st.reason = SolveReason::breakdown;
      return st;
    }
  }
}

}  // namespace tresca
