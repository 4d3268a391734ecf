#include "core/contact/semismooth.hpp"

#include <algorithm>
#include <cmath>
#include <memory>

#include "kernels/contact_maps.hpp"
#include "kernels/vector_ops.hpp"
#include "core/contact/boundary_preconditioner.hpp"
#include "core/util/profile.hpp"

namespace tresca {

const char* to_string(NewtonReason r) {
  switch (r) {
    case NewtonReason::converged: return "converged";
    case NewtonReason::iteration_limit: return "iteration_limit";
    case NewtonReason::stagnation: return "stagnation";
    case NewtonReason::inner_failure: return "inner_solver_failure";
    case NewtonReason::non_finite: return "non_finite";
  }
  return "?";
}

namespace {

// y = mask_F (S x + H x); remembers S x for the incremental update of S u.
class ReducedNewtonOperator : public LinearOperator {
 public:
  ReducedNewtonOperator(const SteklovPoincare& S, const std::vector<real>& h, const std::vector<std::uint8_t>& free)
      : Sx(S.size()), S_(S), h_(h), free_(free) {}
  index size() const override { return S_.size(); }
  void apply(const real* x, real* y) const override {
    S_.apply(x, Sx.data());
    const index p = S_.size() / 3;
    for (index i = 0; i < p; ++i) {
      y[i] = Sx[i] + h_[i] * x[i] + h_[p + i] * x[p + i];
      y[p + i] = Sx[p + i] + h_[p + i] * x[i] + h_[2 * p + i] * x[p + i];
      y[2 * p + i] = Sx[2 * p + i];
    }
    for (index i = 0; i < 3 * p; ++i)
      if (!free_[i]) y[i] = 0;
  }
  mutable std::vector<real> Sx;

 private:
  const SteklovPoincare& S_;
  const std::vector<real>& h_;
  const std::vector<std::uint8_t>& free_;
};

// The reduced Newton system of one step (method.md §4).
struct ReducedSystem {
  explicit ReducedSystem(index n3) : known(n3), h(n3), rhs(n3), fixed(n3), free(n3) {}
  std::vector<real> known;  // known increments: Δu_τ = v_12 (sticking), Δu_z = v_4 (contact)
  std::vector<real> h;      // H_1 blocks (h11 | h12 | h22) of sliding nodes
  std::vector<real> rhs;    // r_F: (I + H_1) v_12 on sliding rows, v_3 + v_4 on separated u_z rows
  std::vector<std::uint8_t> fixed, free;  // per dof: increment known / part of F
};

// Fills L from the node status and the approximation step (v, d); returns
// whether any known increment is nonzero.
bool linearise(index p, real phi, const std::vector<std::uint8_t>& status, const std::vector<real>& v,
               const std::vector<real>& d, ReducedSystem& L) {
  bool any_known = false;
  for (index i = 0; i < p; ++i) {
    const bool stick = status[i] & kStick, contact = status[i] & kContact;
    const real v1 = v[i], v2 = v[p + i], v3 = v[2 * p + i], v4 = v[3 * p + i];
    L.fixed[i] = L.fixed[p + i] = stick;
    L.fixed[2 * p + i] = contact;
    L.free[i] = L.free[p + i] = !stick;
    L.free[2 * p + i] = !contact;
    real h11 = 0, h12 = 0, h22 = 0;
    if (!stick) sliding_block(phi, d[i], d[p + i], h11, h12, h22);
    L.h[i] = h11;
    L.h[p + i] = h12;
    L.h[2 * p + i] = h22;
    L.known[i] = stick ? v1 : 0;
    L.known[p + i] = stick ? v2 : 0;
    L.known[2 * p + i] = contact ? v4 : 0;
    L.rhs[i] = stick ? 0 : v1 + h11 * v1 + h12 * v2;
    L.rhs[p + i] = stick ? 0 : v2 + h12 * v1 + h22 * v2;
    L.rhs[2 * p + i] = contact ? 0 : v3 + v4;
    any_known = any_known || L.known[i] != 0 || L.known[p + i] != 0 || L.known[2 * p + i] != 0;
  }
  return any_known;
}

}  // namespace

NewtonResult semismooth_newton(const SteklovPoincare& S, const std::vector<real>& btilde, real phi,
                               const NewtonOptions& opt) {
  const double t0 = wall_time();
  const index p = S.size() / 3, n3 = 3 * p;
  const InnerStats inner0 = S.stats();
  NewtonResult R;
  R.u.assign(n3, 0);
  R.lambda.assign(p, 0);
  R.Su.assign(n3, 0);
  R.status.assign(p, 0);
  if (opt.u0 && opt.lambda0) {
    R.u = *opt.u0;
    R.lambda = *opt.lambda0;
    const real keep = S.inner_rtol();
    S.set_inner_rtol(1e-12);
    S.apply(R.u.data(), R.Su.data());
    S.set_inner_rtol(keep);
  }
  std::vector<real> r(n3), v(4 * p), d(3 * p), du(n3), Sdu(n3);
  ReducedSystem L(n3);
  std::vector<real>& rhs = L.rhs;
  std::unique_ptr<BoundaryPreconditioner> M;
  if (opt.outer_pc == OuterPreconditioner::multigrid)
    M = std::make_unique<BoundaryPreconditioner>(S, S.interior_multigrid().options());
  ReducedNewtonOperator A(S, L.h, L.free);
  CGWorkspace ws;
  real best = INFINITY;
  int since_best = 0;

  for (int k = 0;; ++k) {
    // residual map and approximation step
    real vnorm;
    {
      ScopedTimer t(Kernel::contact_maps, double(p) * kApproximationStepCost);
      for (index i = 0; i < n3; ++i) r[i] = R.Su[i] - btilde[i];
      vnorm = std::sqrt(approximation_step(p, phi, R.u.data(), R.lambda.data(), r.data(), v.data(), d.data(),
                                           R.status.data()));
    }
    R.history.push_back(vnorm);
    if (opt.progress) {
      NewtonProgress pr{k, vnorm, 0, 0, 0, 0, S.stats().iterations - inner0.iterations, R.outer_iterations,
                        wall_time() - t0};
      for (index i = 0; i < p; ++i) {
        (R.status[i] & kContact ? pr.active : pr.separated) += 1;
        (R.status[i] & kStick ? pr.sticking : pr.sliding) += 1;
      }
      opt.progress(pr);
    }
    if (!std::isfinite(vnorm)) {
      R.reason = NewtonReason::non_finite;
      break;
    }
    if (vnorm <= opt.eps) {
      R.reason = NewtonReason::converged;
      break;
    }
    if (k >= opt.max_iterations) {
      R.reason = NewtonReason::iteration_limit;
      break;
    }
    if (vnorm < best) {
      best = vnorm;
      since_best = 0;
    } else if (++since_best >= opt.stagnation_window) {
      R.reason = NewtonReason::stagnation;
      break;
    }

    // Newton step: known increments, free set, H, right-hand side
    const bool any_known = linearise(p, phi, R.status, v, d, L);
    // Accuracy of the step, absolute: decisions compare forces with phi and
    // u_z, so early steps must be near-exact (1e-10 |v0|); late steps need
    // only a fraction of |v_k|; nothing below 0.1 eps is useful.
    const real target = std::max(0.1 * opt.eps, std::min(opt.step_accuracy * vnorm, 1e-10 * R.history[0]));
    const long long fails0 = S.stats().failures;
    if (any_known) {
      S.set_inner_rtol(1e-12);
      S.apply(L.known.data(), Sdu.data());
      R.operator_applications += 1;
      for (index i = 0; i < n3; ++i)
        if (L.free[i]) rhs[i] -= Sdu[i];
    } else {
      std::fill(Sdu.begin(), Sdu.end(), 0.0);
    }
    if (M) M->update(L.h, L.fixed, L.free);
    CGOptions co;
    co.rtol = 1e-13;  // attainable floor relative to |rhs|
    co.atol = target;
    co.max_iterations = M ? 200 : 5000;
    co.on_step = [&](real alpha) { axpy(n3, alpha, A.Sx.data(), Sdu.data()); };
    // relaxed inner accuracy (Simoncini–Szyld): the perturbation of S may grow
    // like target/|r_j| as the outer residual r_j falls
    co.on_residual = [&](real rn) { S.set_inner_rtol(std::clamp(0.1 * target / rn, 1e-12, 1e-2)); };
    co.abort_if = [&] { return S.stats().failures > fails0; };  // an S apply is untrustworthy
    SolveStats st;
    {
      ScopedTimer t(Kernel::outer_cg);
      st = pcg(A, M.get(), rhs.data(), du.data(), co, ws);
    }
    R.outer_iterations += st.iterations;
    R.operator_applications += st.iterations;
    if (st.reason == SolveReason::max_iterations) R.outer_limit_hits += 1;  // inexact step taken
    if (S.stats().failures > fails0) {
      R.reason = NewtonReason::inner_failure;
      break;
    }
    if (st.reason == SolveReason::non_finite || st.reason == SolveReason::breakdown) {
      R.reason = st.reason == SolveReason::non_finite ? NewtonReason::non_finite : NewtonReason::inner_failure;
      break;
    }
    // update x and S u
    for (index i = 0; i < n3; ++i) du[i] += L.known[i];
    for (index i = 0; i < p; ++i)
      R.lambda[i] += (R.status[i] & kContact) ? Sdu[2 * p + i] - v[2 * p + i] : v[3 * p + i];
    axpy(n3, 1, du.data(), R.u.data());
    axpy(n3, 1, Sdu.data(), R.Su.data());
    R.iterations = k + 1;
  }
  R.inner_iterations = S.stats().iterations - inner0.iterations;
  return R;
}

}  // namespace tresca
