#include "core/solvers/cg.hpp"

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "kernels/vector_ops.hpp"
#include "core/util/profile.hpp"

namespace tresca {

const char* to_string(SolveReason r) {
  switch (r) {
    case SolveReason::converged: return "converged";
    case SolveReason::max_iterations: return "max_iterations";
    case SolveReason::breakdown: return "breakdown";
    case SolveReason::non_finite: return "non_finite";
    case SolveReason::aborted: return "aborted";
  }
  return "?";
}

namespace {

// The CG iteration; `side` is the operator with side products, or null.
SolveStats pcg_impl(const LinearOperator& A, const LinearOperatorWithSide* side, const LinearOperator* M,
                    const real* b, real* x, real* side_x, const CGOptions& opt, CGWorkspace& ws) {
  const index n = A.size();
  if (M && M->size() != n)
    throw std::invalid_argument("pcg: preconditioner size " + std::to_string(M->size()) + " differs from operator size " +
                                std::to_string(n));
  if (!(opt.rtol >= 0) || !(opt.atol >= 0) || opt.max_iterations < 0)
    throw std::invalid_argument("pcg: tolerances must be >= 0 and max_iterations >= 0");
  // a single-precision preconditioner gets r in float, written by the
  // update, and its z is read in float where it is used (operator.hpp)
  const bool in_float = M && M->works_in_float();
  ws.r.resize(n);
  ws.z.resize(in_float ? 0 : n);
  ws.p.resize(n);
  ws.q.resize(n);
  ws.r_low.resize(in_float ? n : 0);
  ws.z_low.resize(in_float ? n : 0);
  if (side) ws.s.resize(side->side_size());
  real *r = ws.r.data(), *z = ws.z.data(), *p = ws.p.data(), *q = ws.q.data(), *sp = ws.s.data();
  float* r_low = in_float ? ws.r_low.data() : nullptr;
  float* z_low = in_float ? ws.z_low.data() : nullptr;
  SolveStats st;
  // local sums -> the sum over all ranks (identity on one rank)
  auto global = [&](real local) { return opt.reduction ? opt.reduction->sum(local) : local; };
  auto apply = [&](real* in, real* out) {
    st.operator_applications += 1;
    A.update_ghosts(in);
    if (side)
      side->apply(in, out, sp);
    else
      A.apply(in, out);
  };
  // r = b - A x, with r's float copy for M and r.r in one sweep (from x =
  // 0, r = b: r.r is b.b, with dot's bits)
  real bb, rr;
  if (opt.zero_initial_guess) {
    fill<real>(n, 0, x);
    if (side && !opt.side_adds) fill<real>(side->side_size(), 0, side_x);
    bb = rr = global(cg_start(n, b, nullptr, r, r_low));
  } else {
    bb = global(dot(n, b, b));
    apply(x, q);
    if (side && opt.side_adds)
      axpy(side->side_size(), 1, sp, side_x);
    else if (side)
      copy(side->side_size(), sp, side_x);
    rr = global(cg_start(n, b, q, r, r_low));
  }
  st.rhs_norm = std::sqrt(bb);
  st.initial_residual = st.residual = std::sqrt(rr);
  const real target = std::max(opt.rtol * st.rhs_norm, opt.atol);
  if (!std::isfinite(rr)) {
    st.reason = SolveReason::non_finite;
    return st;
  }
  if (st.residual <= target) return st;
  if (opt.on_residual) opt.on_residual(st.residual);
  auto precondition = [&] {
    st.preconditioner_applications += 1;
    if (in_float)
      M->apply_in_float(r_low, z_low);
    else if (M)
      M->apply(r, z);
    else
      copy(n, r, z);
  };
  precondition();
  real rz;
  if (in_float) {
    rz = global(cg_first_direction(n, r, z_low, p));
  } else {
    std::swap(z, p);  // p = z without a copy: z is written afresh before it is read again
    rz = global(dot(n, r, p));
  }
  for (int it = 1; it <= opt.max_iterations; ++it) {
    if (!(rz > 0)) {
      st.reason = std::isfinite(rz) ? SolveReason::breakdown : SolveReason::non_finite;
      return st;
    }
    apply(p, q);
    if (opt.abort_if && opt.abort_if()) {
      st.reason = SolveReason::aborted;
      return st;
    }
    real pq;
    {
      ScopedTimer t(Kernel::vector, n * kDotCost);
      pq = global(dot(n, p, q));
    }
    if (!(pq > 0)) {
      st.reason = std::isfinite(pq) ? SolveReason::breakdown : SolveReason::non_finite;
      return st;
    }
    const real alpha = rz / pq;
    if (side) axpy(side->side_size(), alpha, sp, side_x);
    {
      ScopedTimer t(Kernel::vector, n * (in_float ? kCgUpdateFloatRCost : kCgUpdateCost));
      rr = global(in_float ? cg_update(n, alpha, p, q, x, r, r_low) : cg_update(n, alpha, p, q, x, r));
    }
    st.iterations = it;
    st.residual = std::sqrt(rr);
    if (!std::isfinite(rr)) {
      st.reason = SolveReason::non_finite;
      return st;
    }
    if (st.residual <= target) return st;
    if (opt.on_residual) opt.on_residual(st.residual);
    precondition();
    ScopedTimer t(Kernel::vector, n * (in_float ? kDotFloatYCost + kXpayFloatXCost : kDotCost + kXpayCost));
    const real rz_new = global(in_float ? dot(n, r, z_low) : dot(n, r, z));
    if (in_float)
      xpay(n, z_low, rz_new / rz, p);
    else
      xpay(n, z, rz_new / rz, p);
    rz = rz_new;
  }
  st.reason = SolveReason::max_iterations;
  return st;
}

}  // namespace

SolveStats pcg(const LinearOperator& A, const LinearOperator* M, const real* b, real* x, const CGOptions& opt,
               CGWorkspace& ws) {
  return pcg_impl(A, nullptr, M, b, x, nullptr, opt, ws);
}

SolveStats pcg(const LinearOperatorWithSide& A, const LinearOperator* M, const real* b, real* x, real* side_x,
               const CGOptions& opt, CGWorkspace& ws) {
  return pcg_impl(A, &A, M, b, x, side_x, opt, ws);
}

}  // namespace tresca
