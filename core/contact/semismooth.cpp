#include "core/contact/semismooth.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include "kernels/contact_maps.hpp"
#include "kernels/element.hpp"
#include "kernels/launch.hpp"
#include "kernels/vector_ops.hpp"
#include "core/contact/boundary_preconditioner.hpp"
#include "core/solvers/gmres.hpp"
#include "core/util/profile.hpp"

namespace tresca {

const char* to_string(NewtonReason r) {
  switch (r) {
    case NewtonReason::converged: return "converged";
    case NewtonReason::iteration_limit: return "iteration_limit";
    case NewtonReason::stagnation: return "stagnation";
    case NewtonReason::inner_failure: return "inner_solver_failure";
    case NewtonReason::non_finite: return "non_finite";
    case NewtonReason::outer_failure: return "outer_solver_failure";
  }
  return "?";
}

namespace {

// Inner (K_ii) work of the S applications of one Newton solve.
struct InnerWork {
  long long iterations = 0, failures = 0;
  double fine_matvecs = 0;  // SteklovPoincare::apply_work of each application
  // every inner tolerance is divided by this (>= 1): raised where a step's
  // system, checked with a fresh S Δu, missed its accuracy
  // (NewtonSolve::check_step; NewtonResult::inner_tightening)
  real tightening = 1;
  // one application of S at inner tolerance rtol, counted; false if the inner solve failed
  bool apply(const SteklovPoincare& S, const real* v, real* Sv, real rtol, real* extension = nullptr,
             const real* guess = nullptr) {
    return count(S, S.apply(v, Sv, tight(rtol), extension, guess));
  }
  // r = S u - b̃ (SteklovPoincare::residual), counted the same way
  bool residual(const SteklovPoincare& S, const real* u, real* r, real rtol, real* body, const real* guess) {
    return count(S, S.residual(u, r, tight(rtol), body, guess));
  }

 private:
  real tight(real rtol) const { return std::max(real(1e-12), rtol / tightening); }
  bool count(const SteklovPoincare& S, const SolveStats& st) {
    iterations += st.iterations;
    failures += st.ok() ? 0 : 1;
    fine_matvecs += S.apply_work(st.iterations);
    return st.ok();
  }
};

// The reduced Newton system of one step (method.md §4), where the launches run.
struct ReducedSystem {
  explicit ReducedSystem(index n3)
      : known(n3), known_product(n3), h(n3), rhs(n3), dlambda(n3 / 3), coupling(2 * (n3 / 3)), fixed(n3), free(n3) {}
  Field<real> known;  // known increments: Δu_τ = v_12 (sticking), Δu_z = v_4 / s (contact)
  Field<real> known_product;  // S Δu_known as subtracted from rhs (0: not applied)
  Field<real> h;      // H_1 blocks (h11 | h12 | h22) of sliding nodes
  Field<real> rhs;    // r_F: (s I + H_1) v_12 on sliding rows, v_3 + v_4 on separated u_z rows
  Field<real> dlambda;  // Δλ = v_4 (separated), −v_3 (contact: plus (S Δu)_z)
  // Coulomb Newton: F t per sliding contact node (2 blocks of p; t = d_12/|d_12|),
  // the τ rows' coefficient of (S Δu)_z; zero on all other nodes
  Field<real> coupling;
  bool coupled = false;
  Field<std::uint8_t> fixed, free;  // per dof: increment known / part of F
  // what a launch reads of the reduced operator (reduced_rows)
  struct View {
    const real *h, *coupling;
    const std::uint8_t* free;
    bool coupled;
  };
  View view() const { return {h.data(), coupling.data(), free.data(), coupled}; }
};

// One point x = (u, lambda) of the iteration with r = S u - b̃, its bound
// and its approximation step (contact_maps.hpp), where the launches run.
struct Point {
  Field<real> u, lambda, r;    // 3p, p, 3p
  Field<real> phi;             // its Tresca bound (Coulomb: from this point's lambda)
  Field<real> v, w, d;         // v̂ (4p), w (4p), d (3p)
  Field<std::uint8_t> status;  // p
  explicit Point(index p) : u(3 * p), lambda(p), r(3 * p), phi(p), v(4 * p), w(4 * p), d(3 * p), status(p) {}
};

// Fills L from the node status and the approximation step d at scale s
// (contact_maps.hpp) of x: with v_12 = d_12 − u_τ, v_4 = d_4 − lambda the
// scaled step's increments and v_3 = v̂_3, the linearisation of (8) at (x, d̂) gives
//   sticking: Δu_τ = v_12;  sliding: (S Δu)_τ + H_1 Δu_τ = (s I + H_1) v_12
//   contact: Δu_z = v_4 / s;  separated: Δλ = v_4, (S Δu)_z = v_3 + v_4
// (s = 1: the paper's (G A + H) Δ = (G + H) v̂). Returns whether any known
// increment is nonzero.
//
// Coulomb (F >= 0, coupled): the step's point on the Coulomb graph has the
// pressure d_4 and the bound phi = F d_4 (the Newton loop computes d_12 with
// it). Its friction force moves with the pressure, so the linearised sliding
// law of a node in contact gains F t (λ_new − d_4), t = d_12/|d_12|:
//   (S Δu)_τ + H_1 Δu_τ + F t ((S Δu)_z − v_3 − v_4) = (s I + H_1) v_12,
// λ_new = λ + Δλ with Δλ = (S Δu)_z − v_3: a coupling to the z row of S Δu
// (L.coupling) and a known term. Separated nodes have phi = F d_4 = 0 and
// stay uncoupled.
bool linearise(index p, const real* scale, const Point& x, const FrictionLaw& friction, ReducedSystem& L) {
  L.coupled = friction.differentiates_bound();
  const bool coupled = L.coupled;
  const real F = friction.F;
  const real *u = x.u.data(), *lambda = x.lambda.data(), *vhat = x.v.data(), *d = x.d.data(), *phi = x.phi.data();
  const std::uint8_t* status = x.status.data();
  real *known = L.known.data(), *h = L.h.data(), *rhs = L.rhs.data(), *dlambda = L.dlambda.data(),
       *coupling = L.coupling.data();
  std::uint8_t *fixed = L.fixed.data(), *free = L.free.data();
  for_each_entry("newton-step system", p, Cost{81, 30}, [=](index i) {
    const bool stick = status[i] & kStick, contact = status[i] & kContact;
    const real s = scale ? scale[i] : 1;
    const real v1 = d[i] - u[i], v2 = d[p + i] - u[p + i], v3 = vhat[2 * p + i], v4 = d[2 * p + i] - lambda[i];
    fixed[i] = fixed[p + i] = stick;
    fixed[2 * p + i] = contact;
    free[i] = free[p + i] = !stick;
    free[2 * p + i] = !contact;
    real h11 = 0, h12 = 0, h22 = 0;
    if (!stick) sliding_block(phi[i], d[i], d[p + i], h11, h12, h22);
    h[i] = h11;
    h[p + i] = h12;
    h[2 * p + i] = h22;
    known[i] = stick ? v1 : 0;
    known[p + i] = stick ? v2 : 0;
    known[2 * p + i] = contact ? v4 / s : 0;
    dlambda[i] = contact ? -v3 : v4;  // + (S Δu)_z on contact nodes, after the solve
    real r1 = stick ? 0 : s * v1 + h11 * v1 + h12 * v2;
    real r2 = stick ? 0 : s * v2 + h12 * v1 + h22 * v2;
    rhs[2 * p + i] = contact ? 0 : v3 + v4;
    coupling[i] = coupling[p + i] = 0;
    if (coupled && !stick && contact) {
      const real n = std::hypot(d[i], d[p + i]);
      const real tx = F * d[i] / n, ty = F * d[p + i] / n;
      const real dl = -v3 - v4;  // the known part of λ_new − d_4
      r1 -= tx * dl;
      r2 -= ty * dl;
      coupling[i] = tx;
      coupling[p + i] = ty;
    }
    rhs[i] = r1;
    rhs[p + i] = r2;
  });
  const real nodes_known = sum_over_entries("newton-step known nodes", p, Cost{24, 0}, [=](index i) {
    return real(known[i] != 0 || known[p + i] != 0 || known[2 * p + i] != 0);
  });
  return nodes_known > 0;
}

// rhs -= mask_F (S Δu_known (+ F t (S Δu_known)_z: Coulomb Newton)), with
// Sk = S Δu_known: the known increments' part of the right-hand side
void subtract_known(const ReducedSystem& L, index p, const real* Sk, real* rhs) {
  const real* coupling = L.coupling.data();
  const std::uint8_t* free = L.free.data();
  const bool coupled = L.coupled;
  for_each_entry("newton-step recover", p, Cost{67, 5}, [=](index i) {
    for (int a = 0; a < 3; ++a) {
      const index k = a * p + i;
      if (!free[k]) continue;
      real y = rhs[k] - Sk[k];
      if (coupled && a < 2) y -= coupling[k] * Sk[2 * p + i];
      rhs[k] = y;
    }
  });
}

// The rows (y0, y1, y2) of S x + H x (+ F t (S x)_z: Coulomb Newton) at node
// i, from (s0, s1, s2) = (S x)_i. No arrays: a launch's body that passed
// local arrays to it was miscompiled by GCC 12 for the GPU (the arrays went to
// its lanes' private stack, and the callee's reads and writes were dropped:
// the rows were never computed, RESULTS.md §0zg). These scalar references
// are inlined away first, as tests/check_device_code.py verifies.
inline void reduced_rows(index p, index i, real s0, real s1, real s2, const real* x, const ReducedSystem::View& L,
                         real& y0, real& y1, real& y2) {
  y0 = s0 + L.h[i] * x[i] + L.h[p + i] * x[p + i];
  y1 = s1 + L.h[p + i] * x[i] + L.h[2 * p + i] * x[p + i];
  y2 = s2;
  if (L.coupled) {
    y0 += L.coupling[i] * y2;
    y1 += L.coupling[p + i] * y2;
  }
}

// y = mask_F (S x + H x (+ F t (S x)_z: Coulomb Newton)), with the side
// product [S x | E x] (3p + S.full_size()): the CG accumulates both along its
// iterate, so after the step it holds the running S Δu_F, whose norm sets the
// accuracy of the update's apply of S Δu, and E Δu_F, that apply's initial
// guess. The inner tolerance is this step's own state, relaxed as its outer
// CG converges.
class ReducedNewtonOperator : public LinearOperatorWithSide {
 public:
  ReducedNewtonOperator(const SteklovPoincare& S, const ReducedSystem& L, InnerWork& work)
      : S_(S), L_(L), work_(work) {}
  index size() const override { return S_.size(); }
  index side_size() const override { return S_.size() + S_.full_size(); }
  void set_inner_rtol(real r) { rtol_ = r; }
  void apply(const real* x, real* y, real* side) const override { apply(x, y, side, side + S_.size()); }
  void apply(const real* x, real* y) const override {
    Sx_.resize(S_.size());  // (GMRES: no side product, so no 3D extension either)
    apply(x, y, Sx_.data(), nullptr);
  }

 private:
  // y as above and Sx = S x; E x into `extension` if not null
  void apply(const real* x, real* y, real* Sx, real* extension) const {
    work_.apply(S_, x, Sx, rtol_, extension);
    const index p = S_.size() / 3;
    const ReducedSystem::View L = L_.view();
    for_each_entry("newton-step operator", p, Cost{123, 12}, [=](index i) {
      real y0, y1, y2;
      reduced_rows(p, i, Sx[i], Sx[p + i], Sx[2 * p + i], x, L, y0, y1, y2);
      y[i] = L.free[i] ? y0 : 0;
      y[p + i] = L.free[p + i] ? y1 : 0;
      y[2 * p + i] = L.free[2 * p + i] ? y2 : 0;
    });
  }

  const SteklovPoincare& S_;
  const ReducedSystem& L_;
  InnerWork& work_;
  real rtol_ = 1e-12;
  mutable Field<real> Sx_;
};

// The result of solving one reduced Newton system.
struct StepOutcome {
  SolveStats outer;
  real rhs_norm = 0, target = 0;  // |r_F|, and the accuracy asked of the system's residual
  bool inner_failed = false;
  bool known_applied = false;  // S was applied to the known increments
};

// Solves the reduced system of L for Δu_F (into du) to the relative
// accuracy eta (forcing term; semismooth.hpp: Tolerances), floored at the
// absolute `floor`; side gets the estimates [S Δu | E Δu] of the whole step:
// the known increments' (applied first), then the CG's running ones added
// (inexact; GMRES: the known part only).
StepOutcome solve_step(const SteklovPoincare& S, ReducedSystem& L, BoundaryPreconditioner* M, real eta, real floor,
                       real s_bound, bool any_known, InnerWork& work, CGWorkspace& ws, Field<real>& du,
                       Field<real>& side) {
  const index n3 = S.size(), nf = S.full_size();
  real* known = side.data();  // [S Δu_known | E Δu_known], then the CG's added
  StepOutcome out;
  const long long fails0 = work.failures;
  auto norm = [&](const real* x) { return std::sqrt(S.sum(dot(n3, x, x))); };
  // known increments enter the right-hand side: r_F -= (S Δu_known)_F; an
  // error there is an error of the step: to a tenth of the step's target
  // eta |r_F| absolute, with |S Δu_known| <= s_bound |Δu_known|. Known
  // increments too small to matter at that accuracy (e.g. u_z already on
  // the obstacle) are not applied: the update's apply of S Δu has them.
  // (Coulomb Newton: the coupling F t (S Δu_known)_z too, at 0.1 eta.)
  const real inner_max = 1e-2;
  const real known_bound = any_known ? s_bound * norm(L.known.data()) : 0;
  const real known_accuracy = 0.1 * std::max(floor, eta * norm(L.rhs.data()));
  out.known_applied = any_known && (L.coupled || known_bound > known_accuracy);
  if (out.known_applied) {
    const real rtol = L.coupled ? 0.1 * eta : known_accuracy / known_bound;
    if (!work.apply(S, L.known.data(), known, std::clamp(rtol, real(1e-12), inner_max), known + n3)) {
      out.inner_failed = true;
      return out;
    }
    subtract_known(L, n3 / 3, known, L.rhs.data());
    copy(n3, known, L.known_product.data());
  } else {
    fill<real>(n3 + nf, 0, known);
    fill<real>(n3, 0, L.known_product.data());
  }
  if (M) M->update(L.h, L.fixed, L.free);
  ReducedNewtonOperator A(S, L, work);
  CGOptions co;
  out.rhs_norm = norm(L.rhs.data());
  const real target = std::max(floor, eta * out.rhs_norm);
  out.target = target;
  co.rtol = 1e-13;  // attainable floor relative to |rhs|
  co.atol = target;
  co.max_iterations = M ? 200 : 5000;
  // relaxed inner accuracy (Simoncini–Szyld): the perturbation of S may grow
  // like target/|r_j| as the outer residual r_j falls
  co.on_residual = [&](real rn) { A.set_inner_rtol(std::clamp(target / rn, real(1e-12), inner_max)); };
  co.abort_if = [&] { return work.failures > fails0; };  // an S apply is untrustworthy
  co.reduction = &S.comm();  // contact vectors over the ranks (Comm::self() when not split)
  if (L.coupled) {
    // not symmetric: GMRES with the same preconditioner. The inner accuracy
    // is fixed at 0.3 eta (tighter costs more work, looser and relaxing it as
    // for CG cost Newton steps: perf/RESULTS.md §0e). S Δu is not a side product
    // here (the update's apply of S Δu bounds it by smax |Δu|)
    GMRESOptions go;
    go.atol = target;
    go.rtol = 1e-13;
    go.restart = 50;
    go.max_iterations = co.max_iterations;
    A.set_inner_rtol(std::clamp(0.3 * eta, real(1e-12), inner_max));
    go.abort_if = co.abort_if;
    go.reduction = co.reduction;
    ScopedTimer t(Kernel::outer_cg);
    out.outer = gmres(A, M, L.rhs.data(), du.data(), go);
  } else {
    ScopedTimer t(Kernel::outer_cg);
    co.side_adds = true;  // onto the known increments' part
    out.outer = pcg(A, M, L.rhs.data(), du.data(), side.data(), co, ws);
  }
  if (M) work.fine_matvecs += out.outer.preconditioner_applications * M->apply_work();
  out.inner_failed = work.failures > fails0;
  return out;
}

}  // namespace

std::vector<real> step_scale(const SteklovPoincare& S) {
  const std::vector<real> kd = S.contact_diagonal();
  const index p = S.size() / 3;
  std::vector<real> s(p);
  for (index c = 0; c < p; ++c) s[c] = (kd[c] + kd[p + c] + kd[2 * p + c]) / 3;
  return s;
}

real contact_stiffness_bound(const Problem& P) {
  std::array<real, 576> Ke;
  brick_stiffness(P.grid.hx(), P.grid.hy(), P.grid.hz(), P.spec.E, P.spec.nu, Ke.data());
  real row = 0;
  for (int r = 0; r < 24; ++r) {
    real sum = 0;
    for (int q = 0; q < 24; ++q) sum += std::abs(Ke[24 * r + q]);
    row = std::max(row, sum);
  }
  return 4 * row;
}

bool stagnated(const std::vector<real>& h, int w, int from) {
  const int k = int(h.size()) - from;
  if (w <= 0 || k <= w) return false;
  const real before = *std::min_element(h.begin() + from, h.end() - w);
  const real last = *std::min_element(h.end() - w, h.end());
  return last > 0.5 * before;
}

namespace {

// the initial iterates' sizes, and every node's bound and gap: throws
// std::invalid_argument naming what is wrong
void check_inputs(index p, index nf, const ContactConditions& law, const NewtonOptions& opt) {
  const index n3 = 3 * p;
  auto size_error = [](const char* what, size_t got, index want) {
    throw std::invalid_argument(std::string("semismooth_newton: ") + what + " has " + std::to_string(got) +
                                " entries, expected " + std::to_string(want));
  };
  if (opt.u0 && index(opt.u0->size()) != n3) size_error("u0", opt.u0->size(), n3);
  if (opt.lambda0 && index(opt.lambda0->size()) != p) size_error("lambda0", opt.lambda0->size(), p);
  if (opt.r0 && index(opt.r0->size()) != n3) size_error("r0", opt.r0->size(), n3);
  if (opt.body0 && index(opt.body0->size()) != nf) size_error("body0", opt.body0->size(), nf);
  if (!(opt.inner_tightening >= 1 && std::isfinite(opt.inner_tightening)))
    throw std::invalid_argument("semismooth_newton: inner_tightening " + std::to_string(opt.inner_tightening) +
                                " must be >= 1 and finite");
  if (opt.r0 && !(opt.body0 && opt.force_scale > 0))
    throw std::invalid_argument("semismooth_newton: r0 needs the body it came from (body0) and force_scale");
  const std::vector<real>& phi = law.phi;
  if (index(phi.size()) != p) size_error("phi", phi.size(), p);
  if (index(law.gap.size()) != p) size_error("gap", law.gap.size(), p);
  for (index i = 0; i < p; ++i) {
    if (!(phi[i] >= 0) || !std::isfinite(phi[i]))
      throw std::invalid_argument("semismooth_newton: phi of contact node " + std::to_string(i) + " = " +
                                  std::to_string(phi[i]) + " must be >= 0 and finite");
    if (!(law.gap[i] >= 0) || !std::isfinite(law.gap[i]))
      throw std::invalid_argument("semismooth_newton: gap of contact node " + std::to_string(i) + " = " +
                                  std::to_string(law.gap[i]) + " must be >= 0 and finite");
  }
  if (opt.u0 && !(opt.force_scale > 0))
    throw std::invalid_argument("semismooth_newton: an initial iterate u0 needs force_scale = |b~|");
}

// The forcing term of step k (Eisenstat–Walker, choice 2, safeguarded): the
// step is solved to eta_k relative, eta_k -> 0 as |v̂| falls (superlinear),
// but no finer than the stopping rule needs: a step that reduces |v̂| by
// about tol/|v̂| is enough to stop after it (Kelley's safeguard against
// oversolving the last step, with the factor 0.1: perf/RESULTS.md §0f)
real forcing_term(const NewtonOptions& opt, int k, real vnorm, real previous, real eta, real tol) {
  real eta_k = eta;
  if (k > 0) {
    const real ratio = vnorm / previous;
    eta_k = std::min(opt.forcing_max, real(0.9) * ratio * ratio);
    if (0.9 * eta * eta > 0.1) eta_k = std::max(eta_k, real(0.9) * eta * eta);
  }
  return std::min(opt.forcing_max, std::max(eta_k, real(0.1) * tol / vnorm));
}

// the progress of iteration k to the caller: states counted over all ranks,
// the iterate in host copies (p-sized: once per Newton step)
void report_progress(const SteklovPoincare& S, const NewtonResult& R, const Point& x, int k, real vnorm,
                     long long inner, double seconds, const std::function<void(const NewtonProgress&)>& progress) {
  const StateCounts c = count_states(S.contact_nodes(), x.status.data());
  const std::vector<real> u = x.u.to_vector(), lambda = x.lambda.to_vector(), r = x.r.to_vector(),
                          phi = x.phi.to_vector();
  const std::vector<std::uint8_t> status = x.status.to_vector();
  NewtonProgress pr{k, vnorm, 0, 0, 0, 0, inner, R.outer_iterations, seconds, &u, &lambda, &r, &status, &phi};
  pr.separated = index(S.sum(real(c.separated)));
  pr.sticking = index(S.sum(real(c.stick)));
  pr.sliding = index(S.sum(real(c.slip)));
  pr.active = pr.sticking + pr.sliding;
  pr.step_length = R.step_lengths.empty() ? 1 : R.step_lengths.back();
  progress(pr);
}

// The backtracking line search: with envelope_at, the full step where it
// halves the least |w| so far (Newton's own convergence: the envelope in
// the metric s, which need not bound S, can rise along a step that cuts
// |w| by orders of magnitude, and a Coulomb fixed point's Tresca solves
// stagnated at lengths 2^-8, RESULTS.md §0zs; halving the last |w| alone
// let Newton cycle between two sets of states, |w| 2.0e6 and 6.7e6 N,
// each full step halving the half step's |w| before it while the energy
// rose, §0zx); else the first alpha = 2^-j, j = 0 ..
// halvings, that lowers the forward-backward envelope where envelope_at(alpha)
// resolves its change, and elsewhere (and without envelope_at) whose
// merit_at(alpha) <= (1 - 1e-4 alpha) times the largest of the last
// memory + 1 merits (non-monotone, GLL); where the envelope rises at every
// length (s below S's scale: not a descent direction), the first alpha by
// |w| alone; 0 if there is none. by_envelope: the envelope chose alpha.
struct StepLength {
  real alpha = 0;
  bool by_envelope = false;
};
StepLength line_search(const std::vector<real>& merits, int memory, int halvings,
                       const std::function<real(real)>& merit_at,
                       const std::function<std::optional<real>(real)>& envelope_at) {
  const int m = std::min<int>(memory + 1, int(merits.size()));
  const real reference = *std::max_element(merits.end() - m, merits.end());
  // (the full step's merit, asked once)
  std::optional<real> full;
  auto merit = [&](real alpha) { return alpha == 1 ? (full ? *full : *(full = merit_at(1))) : merit_at(alpha); };
  if (envelope_at && merit(1) <= 0.5 * *std::min_element(merits.begin(), merits.end())) return {1, false};
  real alpha = 1;
  for (int j = 0; j <= halvings; ++j, alpha *= 0.5) {
    if (const std::optional<real> change = envelope_at ? envelope_at(alpha) : std::nullopt) {
      if (*change < 0) return {alpha, true};
    } else if (merit(alpha) <= (1 - 1e-4 * alpha) * reference) {
      return {alpha, false};
    }
  }
  return envelope_at ? line_search(merits, memory, halvings, merit_at, {}) : StepLength{};
}

// One semismooth* Newton solve (semismooth_newton): its state and its steps.
// Every vector of the iteration lives where the launches run; the options'
// initial values come in, and the result's values go out, as host copies.
class NewtonSolve {
 public:
  NewtonSolve(const SteklovPoincare& S, const ContactConditions& given, const NewtonOptions& opt);
  NewtonResult run();

 private:
  NewtonResult finish(NewtonReason reason);
  bool start();
  bool refresh(real rtol);
  ResidualNorms residual_at(Point& at);
  void approximate();
  bool measure(int k);
  std::optional<NewtonReason> record(int k);
  std::optional<NewtonReason> floor_stop(int k);
  real floor_cap(real level, real& measured);
  std::optional<NewtonReason> newton_step();
  std::optional<NewtonReason> take_step();
  bool check_step(const real* Sdu, bool hit_limit);
  std::function<std::optional<real>(real)> envelope_along_step(const real* Sdu);

  const SteklovPoincare& S;
  const NewtonOptions& opt;
  const double t0;
  const index p, n3, nf;
  InnerWork work;
  NewtonResult R;
  real fscale = 1;  // |b̃|
  // the line search's merit far from the solution is an energy's envelope
  // (NewtonOptions::envelope_merit: envelope_along_step, record)
  bool descends_energy() const { return opt.envelope_merit && envelope_applies(opt.scaling, opt.friction); }
  // what r resolves at its tightest (Tolerances: residual_accuracy |b̃|)
  real resolved() const { return opt.residual_accuracy * fscale; }
  real r_err = 0;   // bounds the error of the current r
  bool r_fresh = false;       // r solved from the body at this iterate (refresh), not summed from steps
  bool stop_verified = false;  // this iterate's stop, believed on a summed r, confirmed by a fresh one
  Field<real> gap;              // the law's gaps
  Field<real> units;            // the stiffness of the consistent units
  const real* scale_ptr = nullptr;  // the step's metric: units, or nullptr (the paper's s = 1)
  // the iterate x, and a trial point of the line search (its own bound:
  // Coulomb's bound of a rejected trial must not outlive it)
  Point x, trial;
  Field<std::uint8_t> last_status;  // x's node states at the last recorded iterate
  // side: [S Δu | E Δu] of the step
  Field<real> du, side, dlambda;
  ReducedSystem L;
  std::unique_ptr<BoundaryPreconditioner> M;
  CGWorkspace ws;
  real smax = 0;  // |S x| <= smax |x|
  bool last_step_hit_limit = false;  // this step's outer CG stopped at its limit (newton_step)
  bool taken_at_limit = false;       // so did the last step taken
  real step_tightening = 1;  // the inner tightening when this step's solve began
  bool redo = false;         // this iteration's step is to be solved again (take_step)
  int redos = 0;             // times this iteration's step was solved again
  static constexpr int kMaxRedos = 3;
  static constexpr real kStallTightening = 10;  // the least a step stopped at the outer limit tightens by
  static constexpr real kMeasuredFloorMax = 1e-6;  // relative to |b̃|: floor_cap
  static constexpr real kFloorSpread = 4;          // floor_cap
  real step_rhs = 0, step_target = 0;  // the last step's |r_F| and accuracy asked (StepOutcome)
  real last_missed = 0;                // the factor the last step missed its accuracy by (check_step), 0: met
  int last_watchdog = std::numeric_limits<int>::min() / 2;  // the last step the watchdog took whole
  int last_change = 0;  // the last iteration whose step changed some node's state
  int window_from = 0;  // the stagnation window's first iteration (floor_stop: r refreshed there)
  real eta;
  // this iteration's |v̂|, merit |w| and tolerance
  real vnorm = 0, merit = 0, tol = 0;
};

NewtonSolve::NewtonSolve(const SteklovPoincare& S_, const ContactConditions& given, const NewtonOptions& opt_)
    : S(S_),
      opt(opt_),
      t0(wall_time()),
      p(S_.size() / 3),
      n3(3 * p),
      nf(S_.full_size()),
      x(p),
      trial(p),
      last_status(p),
      du(n3),
      side(n3 + nf),
      dlambda(p),
      L(n3),
      eta(opt_.forcing_max) {
  // Coulomb: the bound follows lambda at every iteration
  if (opt.friction.is_coulomb() && !opt.friction.bound_follows_lambda())
    throw std::invalid_argument("semismooth_newton: a Coulomb fixed point runs whole Tresca solves (coulomb.hpp)");
  check_inputs(p, nf, given, opt);
  x.phi = placed_field<real>(given.phi);
  trial.phi = x.phi;
  gap = placed_field<real>(given.gap);
  // the approximation step's metric (contact_maps.hpp): the paper's (s = 1) or
  // s_i = mean diagonal of K_cc at contact node i; kept in the result for
  // the final report's status. The residual in consistent units is measured
  // in the stiffness of the diagonal metric whatever the step's metric.
  R.units = step_scale(S);
  work.tightening = opt.inner_tightening;
  R.stop = opt.stop;
  R.kink_contact = opt.kink_contact;
  units = placed_field<real>(R.units);
  if (opt.scaling == StepScaling::diagonal) {
    R.scale = R.units;
    scale_ptr = units.data();  // (the same array: approximation_step then computes the step once)
  }
  if (opt.u0) x.u = placed_field<real>(*opt.u0);
  if (opt.lambda0) x.lambda = placed_field<real>(*opt.lambda0);
  if (opt.body0) {
    R.body = std::move(*opt.body0);  // (taken: NewtonOptions::body0)
    R.body.move_to(launch_space());
  } else {
    R.body = Field<real>(nf);
  }
  if (opt.outer_pc == OuterPreconditioner::multigrid)
    M = std::make_unique<BoundaryPreconditioner>(S, S.mg_options());
  smax = contact_stiffness_bound(S.problem());
}

NewtonResult NewtonSolve::finish(NewtonReason reason) {
  R.reason = reason;
  R.u = x.u.to_vector();
  R.lambda = x.lambda.to_vector();
  R.r = x.r.to_vector();
  R.status = x.status.to_vector();
  R.phi = x.phi.to_vector();
  R.inner_iterations = work.iterations;
  R.fine_matvecs = work.fine_matvecs;
  R.inner_tightening = work.tightening;
  return std::move(R);
}

// r = S u - b̃ to the accuracy its use needs (Tolerances), by a solve warm
// from the body
bool NewtonSolve::refresh(real rtol) {
  R.operator_applications += 1;
  r_fresh = true;
  return work.residual(S, x.u.data(), x.r.data(), std::max(rtol, real(1e-12)), R.body.data(), R.body.data());
}

// the first residual and |b̃| (given, or from x0 = 0, where r0 = -b̃; 1 if
// there is no load at all)
bool NewtonSolve::start() {
  if (opt.r0)
    x.r = placed_field<real>(*opt.r0);
  else if (!refresh(opt.initial_residual_rtol))
    return false;
  R.force_scale =
      opt.force_scale > 0 ? opt.force_scale : force_scale_of(std::sqrt(S.sum(dot(n3, x.r.data(), x.r.data()))));
  fscale = R.force_scale;
  r_err = (opt.r0 ? (opt.r0_accuracy > 0 ? opt.r0_accuracy : opt.residual_accuracy) : opt.initial_residual_rtol) *
          fscale;
  return true;
}

// the approximation step at the point's (u, lambda, r) with its bound
// (Coulomb: phi_i = F lambda_i of that point): its v̂, w, d and status
ResidualNorms NewtonSolve::residual_at(Point& at) {
  if (opt.friction.bound_follows_lambda()) coulomb_bound(p, opt.friction.F, at.lambda.data(), at.phi.data());
  return approximation_step(p, ContactLaw{at.phi.data(), gap.data(), opt.kink_contact}, scale_ptr, units.data(),
                            at.u.data(), at.lambda.data(), at.r.data(), at.v.data(), at.w.data(), at.d.data(),
                            at.status.data());
}

// the approximation step at x: |v̂| and |w|, x's v̂, w, d and node states
void NewtonSolve::approximate() {
  ScopedTimer t(Kernel::contact_maps, double(p) * kApproximationStepCost);
  const ResidualNorms norms = residual_at(x);
  merit = std::sqrt(S.sum(norms.consistent));
  vnorm = opt.stop == StopRule::consistent ? merit : std::sqrt(S.sum(norms.paper));
  if (opt.friction.differentiates_bound()) {
    // the step's point on the Coulomb graph: its pressure d_4 sets the
    // bound of its friction force (v̂, the residual, stays at lambda)
    const real F = opt.friction.F;
    const real* d4 = x.d.data() + 2 * p;
    real* phi = x.phi.data();
    for_each_entry("coulomb bound of d4", p, Cost{16, 1}, [=](index i) { phi[i] = F * d4[i]; });
    approximation_step(p, ContactLaw{phi, gap.data(), opt.kink_contact}, scale_ptr, units.data(), x.u.data(),
                       x.lambda.data(), x.r.data(), trial.v.data(), trial.w.data(), x.d.data(), x.status.data());
  }
}

// 1. the approximation step at x = (u, lambda), r = S u - b̃, and the step's
// forcing term; r is refreshed first if it is not accurate enough for them
// (Tolerances). False: an inner solve failed.
bool NewtonSolve::measure(int k) {
  real eta_k = eta;
  bool verifying = false;
  stop_verified = false;
  for (int pass = 0;; ++pass) {
    approximate();
    tol = std::max(opt.eps, opt.rtol * (k == 0 ? vnorm : R.history[0]));
    eta_k = forcing_term(opt, k, vnorm, k > 0 ? R.history[k - 1] : vnorm, eta, tol);
    // r must be accurate to a fraction of what the step resolves, and to
    // the full accuracy before |v̂| <= tol is believed
    const real need = vnorm <= tol ? resolved()
                                   : std::max(resolved(), opt.residual_fraction * eta_k * vnorm);
    // A stop believed on an r summed from the steps' S Δu is checked with a
    // fresh one: where S is much smaller than its terms (a thin plate), the
    // increments carry more error than their inner tolerance bounds and r
    // drifts from S u - b̃ (by 1.6e-3 N, |b̃| 4.4e6 N, on a plate 2 x 1 x
    // 0.01 m of 64x32x4 elements: the final check failed, kkt_check_failed;
    // RESULTS.md §0zl). The fresh r confirms the stop where it agrees to
    // within what r resolves; else Newton goes on from it.
    if (verifying) {
      stop_verified = vnorm <= std::max(tol, resolved());
      break;
    }
    // (a refresh lowers |v̂| where r's error was most of it, and so the
    // need: a few passes, each continuing the last solve)
    if (r_err <= need && vnorm <= tol && !r_fresh)
      verifying = true;
    else if (r_err <= need || pass == 6 || !std::isfinite(vnorm))
      break;
    if (!refresh(need / fscale)) return false;
    r_err = need;
  }
  eta = eta_k;
  return true;
}

// the iteration's record and progress line, and whether it stops here
std::optional<NewtonReason> NewtonSolve::record(int k) {
  // (a stop a fresh r confirmed to within what r resolves: that bound)
  R.tolerance = stop_verified && vnorm > tol ? resolved() : tol;
  R.history.push_back(vnorm);
  R.merit.push_back(merit);
  R.inner_history.push_back(work.iterations);
  R.outer_history.push_back(R.outer_iterations);
  if (opt.progress) report_progress(S, R, x, k, vnorm, work.iterations, wall_time() - t0, opt.progress);
  if (!std::isfinite(vnorm)) return NewtonReason::non_finite;
  if (vnorm <= tol || stop_verified) return NewtonReason::converged;
  // the nodes whose state the last step changed, over the ranks (every rank
  // decides alike): a step that moved the active set and lowered |w| is
  // progress however slow (a separation front that advances a node a
  // step: RESULTS.md §0zd), not stagnation
  const std::uint8_t* now = x.status.data();
  std::uint8_t* before = last_status.data();
  R.last_state_changes = k == 0 ? 0
                                : index(S.sum(sum_over_entries("newton states changed", p, Cost{2, 1},
                                                               [=](index i) { return real(now[i] != before[i]); })));
  for_each_entry("newton states kept", p, Cost{2, 0}, [=](index i) { before[i] = now[i]; });
  if (R.last_state_changes > 0) last_change = k;
  // after a restart from a fresh r (floor_stop), the r summed from the
  // steps can fall again between the refreshes that put |w| back at the
  // fresh level, which the window test counts as progress: the floor is
  // judged again once a window has passed since the restart (a plate of
  // elements 24:1 alternated between 5e-6 and 6e-4 N to the iteration
  // limit, RESULTS.md §0zt); and at the iteration limit, before it ends
  // the run (a window completed there: a plate of elements 117:1 at
  // 7e-12 |b̃| ended at the limit, §0zu); once an iteration
  const bool at_limit = k >= opt.max_iterations;
  const bool judged = at_limit || (window_from > 0 && k - window_from >= opt.stagnation_window);
  if (judged)
    if (const auto stop = floor_stop(k)) return stop;
  if (at_limit) return NewtonReason::iteration_limit;
  const bool progress = R.last_state_changes > 0 && R.merit[k] < R.merit[k - 1];
  auto stagnating = [&] { return stagnated(R.merit, opt.stagnation_window, std::max(R.monotone_from, window_from)); };
  if (!progress && stagnating()) {
    if (!judged)
      if (const auto stop = floor_stop(k)) return stop;
    if (!stagnating()) return std::nullopt;  // (r refreshed: the window starts again)
    // the non-monotone search let Newton wander (NewtonOptions::line_search):
    // from here on each step must lower the merit, and where that merit
    // descends an energy to its minimiser (the envelope), the window test
    // no longer ends the run; not at the floor of what r resolves, where no
    // search makes progress
    const bool at_floor = *std::min_element(R.merit.begin(), R.merit.end()) <= resolved();
    if (!opt.line_search || opt.line_search_memory == 0 || at_floor || (R.monotone_from >= 0 && !descends_energy()))
      return NewtonReason::stagnation;
    if (R.monotone_from < 0) R.monotone_from = k;
  }
  return std::nullopt;
}

// Stagnation at the floor of what r = S u - b̃ resolves for this problem,
// as observed (NewtonOptions::floor_rtol). Where the window's steps changed
// no node's state, Newton is in its local regime: a step solved to its
// tolerance would cut |w| by its forcing term (1e-2 or less), so a |w|
// that wanders at one level for stagnation_window steps is the error of
// the r it is computed from. Where some |w| of the window is at most
// floor_rtol |b̃| (elsewhere nothing changes), r is solved afresh at x (warm
// from the body, to the tightest inner tolerance). Where that r's |w| is
// within the window's level, and the level is at most floor_rtol |b̃| or
// what a fresh r resolves at x as measured (floor_cap), x is a solution to
// that level: converged, the level the tolerance
// (NewtonResult::residual_floor). Where the fresh r is further from a
// solution than the r summed from the steps, and above what r resolves (r
// drifted: the increments carried more error than counted), Newton goes on
// from the fresh r and the window starts again, once. Otherwise stagnation
// is judged as before, from the fresh r. (Plates and blocks of elements
// 7-60 times longer than wide, whose r resolves 2e-12 to 6e-11 |b̃|, not
// 1e-12, wandered at 1-4 times eps = 1e-6 N until stagnation: RESULTS.md
// §0zr.)
std::optional<NewtonReason> NewtonSolve::floor_stop(int k) {
  const int w = opt.stagnation_window;
  if (k - last_change < w || opt.floor_rtol <= 0 || opt.stop != StopRule::consistent ||
      *std::min_element(R.merit.end() - w, R.merit.end()) > std::max(opt.floor_rtol, kMeasuredFloorMax) * fscale)
    return std::nullopt;
  const auto window = R.merit.end() - w;
  real level = std::max(*std::max_element(window, R.merit.end()), resolved());
  // (the window from its first step that did not halve |w|: Newton's last
  // steps to the floor may open it)
  auto settled = window;
  while (settled + 1 != R.merit.end() && settled[1] <= 0.5 * settled[0]) ++settled;
  const real settled_max = *std::max_element(settled, R.merit.end());
  const real summed = merit;
  if (!refresh(1e-12)) return NewtonReason::inner_failure;
  r_err = resolved();
  approximate();
  R.history.back() = R.merit.back() = merit;
  if (merit <= tol) return NewtonReason::converged;
  // (after a restart from a fresh r that Newton's steps did not halve: the
  // fresh |w| is the level, r's error the same from step to step)
  if (window_from > 0) {
    const real restart_merit = R.merit[size_t(window_from)];  // (the fresh r's |w| there)
    if (merit > 0.5 * restart_merit) level = std::max({level, merit, restart_merit});
  }
  if (merit <= level) {
    real measured = 0;  // (what r resolves, where floor_cap measured it)
    // The window's level, or where that is above the floor, the level |w|
    // settled at after Newton's last steps to it, the fresh |w| included (a
    // block of elements 22:1 went from 3.8 N to 6.5e-6 N in two steps and
    // stayed at 5.9-6.8e-6 N for eight, to the iteration limit: §0zu)
    if (level > floor_cap(level, measured)) level = std::max({settled_max, merit, resolved()});
    if (level <= floor_cap(level, measured)) {
      R.residual_floor = level;
      R.floor_measured = level > opt.floor_rtol * fscale ? measured : 0;
      R.tolerance = level;
      return NewtonReason::converged;
    }
  }
  if (merit > 2 * summed && merit > resolved() && window_from == 0) window_from = k;
  return std::nullopt;
}

// The largest level floor_stop calls the floor of what r resolves:
// floor_rtol |b̃|, and above it (up to kMeasuredFloorMax |b̃|, a sanity
// bound, a solver's usual relative tolerance: the floor grows as the mesh
// is refined; at 1e-8 a plate whose |w| settled at 1.07e-8 |b̃| stagnated,
// where its two fresh r differed by 4.9e-6 |b̃|, RESULTS.md §0zw, and at
// 1e-7 the same plate on a mesh 3 times finer, settled at 1.2e-7 |b̃|
// where they differed by 5.5e-6 |b̃|, §0zx) kFloorSpread
// times what a fresh r resolves at x as measured: the difference between
// the fresh r (warm from the body) and a second one solved from a cold
// start to the same tolerance, which is relative to the interior load (a
// sample of the size of a fresh r's error, not a bound). Where S is a
// small difference of large terms (thin plates: an interior load 1.5e4
// |b̃|), a fresh r at the tightest inner tolerance is exact only to
// 1e-10-1e-9 |b̃|, and Newton's steps, each cancelling the last fresh r's
// error, leave the next one's at that level: stagnation at 1.5e-10 to
// 3.8e-9 |b̃| on elements 11-108:1, where the two fresh r differed by
// 1.5e-9 to 1.3e-5 |b̃| (RESULTS.md §0zt).
real NewtonSolve::floor_cap(real level, real& measured) {
  const real cap = opt.floor_rtol * fscale;
  if (level <= cap || level > kMeasuredFloorMax * fscale) return cap;
  if (measured == 0) {  // (once an iterate)
    real* cold = trial.r.data();
    real* body = side.data() + n3;  // (the step's E Δu: scratch until the next step)
    R.operator_applications += 1;
    if (!work.residual(S, x.u.data(), cold, 1e-12, body, nullptr)) return cap;
    axpy(n3, -1, x.r.data(), cold);
    measured = std::sqrt(S.sum(dot(n3, cold, cold)));
  }
  // (the level is the largest |w| of a window whose fresh r each carry an
  // error of their own, the measurement one difference of two such: their
  // sizes spread by a factor 4 over a window, 0.04-0.17 N on a block of
  // elements 41:1 whose two fresh r differed by 0.065 N, and tighter inner
  // solves do not lower them, the arithmetic's limit: RESULTS.md §0zu)
  return std::max(cap, kFloorSpread * measured);
}

// 2. linearisation: known increments, free set, H, right-hand side, and
// 3. the reduced Newton system, by preconditioned CG on the boundary
std::optional<NewtonReason> NewtonSolve::newton_step() {
  // (any rank's known increments make every rank apply S to them: S is collective)
  const bool any_known = S.max(linearise(p, scale_ptr, x, opt.friction, L) ? 1 : 0) > 0;
  const StepOutcome step = solve_step(S, L, M.get(), eta, 0.1 * tol, smax, any_known, work, ws, du, side);
  R.outer_iterations += step.outer.iterations;
  step_rhs = step.rhs_norm;
  step_target = step.target;
  R.operator_applications += step.outer.iterations + (step.known_applied ? 1 : 0);
  if (step.inner_failed) return NewtonReason::inner_failure;
  if (step.outer.reason == SolveReason::non_finite) return NewtonReason::non_finite;
  if (step.outer.reason == SolveReason::breakdown) return NewtonReason::outer_failure;
  const bool limit = step.outer.reason == SolveReason::max_iterations;
  // (a step at the limit is solved again, take_step; after a step taken at
  // the limit, one whose last redo stops there too ends Newton)
  if (limit && taken_at_limit && redos >= kMaxRedos) return NewtonReason::outer_failure;
  last_step_hit_limit = limit;
  return std::nullopt;
}

// 4. update x = (u, lambda), r = S u - b̃ and the body. The step may be
// inexact, but S Δu must be as accurate as this step's r (its error stays
// in every later r): one application of S to the whole Δu, its inner solve
// warm from the CG's running E Δu, to an absolute accuracy of
// max(residual_accuracy |b̃|, residual_fraction eta_k |v̂_k|). An increment
// has the rounding error of its own size, not of r's, so r is kept by
// increments and refreshed only where it is too loose.
// 5. the step's length: the non-monotone line search on the merit |w|
// (NewtonOptions::line_search); r, lambda and u are linear along it.
std::optional<NewtonReason> NewtonSolve::take_step() {
  axpy(n3, 1, L.known.data(), du.data());
  real* Sdu = side.data();
  real* Edu = side.data() + n3;
  const real accuracy = std::max(resolved(), opt.residual_fraction * eta * vnorm);
  // |S Δu| from the CG's side product, or (GMRES) bounded by max s |Δu|
  const real sdu_norm = L.coupled ? smax * std::sqrt(S.sum(dot(n3, du.data(), du.data())))
                                  : std::sqrt(S.sum(dot(n3, Sdu, Sdu)));
  const real inc_rtol = sdu_norm > 0 ? std::clamp(accuracy / sdu_norm, real(1e-12), real(1e-1)) : real(1e-1);
  R.operator_applications += 1;
  if (!work.apply(S, du.data(), Sdu, inc_rtol, Edu, Edu)) return NewtonReason::inner_failure;
  r_err = std::max(r_err, accuracy);
  // a step check_step finds unfit (worse than none, or stopped at the outer
  // limit short of its target), and has tightened the inner solves for:
  // solved again from the same x, at most kMaxRedos times an iteration
  const bool unfit = check_step(Sdu, last_step_hit_limit);
  if (unfit && work.tightening > step_tightening && redos < kMaxRedos) {
    redo = true;
    redos += 1;
    R.redone_steps += 1;
    return std::nullopt;
  }
  // (the launches' bodies take copies of members, not `this`: a body that
  // read p through it read host memory on a GPU, RESULTS.md §0zf)
  const index np = p;
  {  // Δλ: the known part, plus (S Δu)_z on contact nodes
    const real* known_part = L.dlambda.data();
    const std::uint8_t* status = x.status.data();
    real* dl = dlambda.data();
    for_each_entry("newton-step dlambda", p, Cost{25, 1},
                   [=](index i) { dl[i] = known_part[i] + ((status[i] & kContact) ? Sdu[2 * np + i] : 0); });
  }

  real alpha = 1;
  if (opt.line_search) {
    const int memory = R.monotone_from >= 0 ? 0 : opt.line_search_memory;
    const StepLength length = line_search(R.merit, memory, opt.line_search_halvings, [&](real a) {
      const real *u = x.u.data(), *r = x.r.data(), *lambda = x.lambda.data(), *dU = du.data(), *dl = dlambda.data();
      real *tu = trial.u.data(), *tr = trial.r.data(), *tl = trial.lambda.data();
      for_each_entry("line search trial", p, Cost{128, 14}, [=](index i) {
        for (int c = 0; c < 3; ++c) {
          tu[c * np + i] = u[c * np + i] + a * dU[c * np + i];
          tr[c * np + i] = r[c * np + i] + a * Sdu[c * np + i];
        }
        tl[i] = lambda[i] + a * dl[i];
      });
      ScopedTimer t(Kernel::contact_maps, double(p) * kApproximationStepCost);
      return std::sqrt(S.sum(residual_at(trial).consistent));
    }, envelope_along_step(Sdu));
    alpha = length.alpha;
    R.envelope_steps += length.by_envelope;
    if (alpha == 0) {
      // the watchdog (NewtonOptions::line_search): a step solved to its
      // tolerance is taken whole, once in line_search_memory + 1 steps
      const int k = int(R.step_lengths.size());
      if (last_step_hit_limit || k - last_watchdog <= opt.line_search_memory) return NewtonReason::stagnation;
      last_watchdog = k;
      R.watchdog_steps += 1;
      alpha = 1;
    }
  }
  R.step_lengths.push_back(alpha);
  taken_at_limit = last_step_hit_limit;
  R.outer_limit_hits += taken_at_limit;  // (an inexact step taken)
  axpy(p, alpha, dlambda.data(), x.lambda.data());
  axpy(n3, alpha, du.data(), x.u.data());
  axpy(n3, alpha, Sdu, x.r.data());
  r_fresh = false;
  axpy(nf, alpha, Edu, R.body.data());
  return std::nullopt;
}

// The envelope's change along the step (NewtonOptions::envelope_merit), or
// none where it does not apply: the paper's unscaled step, and a Coulomb
// bound that follows lambda (no energy is minimised there). Its change at
// alpha is alpha du·r + ½ alpha² du·S du + the contact terms' change
// (contact_maps.hpp: envelope_change), unresolved (nullopt) where it is
// within 1e-12 of its terms' magnitude: near the solution, where the
// envelope's change is of the order of |w|² / s, it leaves the decision
// to |w|.
std::function<std::optional<real>(real)> NewtonSolve::envelope_along_step(const real* Sdu) {
  if (!descends_energy()) return {};
  const real* u = x.u.data();
  const real* r = x.r.data();
  const real* d = du.data();
  const ContactLaw law{x.phi.data(), gap.data(), opt.kink_contact};
  // (du·r, du·S du and |du||r|, at the first length asked: a full step that
  // halves the least |w| so far asks none)
  return [=, dots = std::optional<std::array<real, 3>>()](real a) mutable -> std::optional<real> {
    if (!dots)
      dots = {S.sum(dot(n3, d, r)), S.sum(dot(n3, d, Sdu)), std::sqrt(S.sum(dot(n3, d, d)) * S.sum(dot(n3, r, r)))};
    const auto [dr, dsd, cross] = *dots;
    ScopedTimer t(Kernel::contact_maps, 2 * double(p) * kEnvelopeChangeCost);
    const EnvelopeChange e = envelope_change(p, law, scale_ptr, a, u, r, d, Sdu);
    const real change = a * dr + real(0.5) * a * a * dsd + S.sum(e.change);
    if (std::abs(change) <= 1e-12 * (a * cross + S.sum(e.size))) return std::nullopt;
    return change;
  };
}

// The step's system checked with the fresh S Δu (of the whole step, less
// the known increments' S Δu_known as subtracted from r_F): the residual
// |mask_F (S Δu_F + H Δu (+ F t (S Δu_F)_z)) − r_F|. The outer solve met
// `step_target` = eta |r_F| with the S products of its relaxed inner
// solves, whose tolerance is relative to the interior load K_ic x. Where
// S x = K_cc x − K_ci K_ii⁻¹ K_ic x is much smaller than its two terms (a
// material near ν = −1, whose bulk modulus is a hundredth of its shear
// modulus), that tolerance buys less accuracy in S x, the step misses its
// target by the factor lost, and Newton converges only linearly, at about
// that factor times eta (ν = −0.97: 49 steps at level 7, and stagnation at
// ν = −0.99; RESULTS.md §0ze). A step whose residual is left above a
// tenth of r_F (it did not remove 90 % of its own linear model's residual)
// has missed; two steps in a row that missed tighten every later inner
// tolerance by the smaller factor they missed their targets by. (One miss
// alone may be the step's own: a cold start's free fall over a gap leaves
// 0.2 r_F with ν = 0.45, and the next step meets its target.) A step whose
// outer CG stopped at its iteration limit short of its target tightens at
// once, by the factor it fell short by and at least kStallTightening, even
// where it removed 90 % of r_F: CG lost its way on S products too inexact
// to converge (a plate 2 x 1 x 0.0125 m of 32x16x4 elements, RESULTS.md
// §0zl; plates 2 x 1 x 0.0098-0.0101 m of 64x32x4 elements after steps
// that removed 99 % of r_F, §0zp; elements 20-750 times longer than wide
// stopped there step after step, by 1.5-200 times their targets, §0zt).
// So does a step left worse than none, by the factor it missed its target
// by (its residual above r_F itself: 1.3 r_F, 129 times its target, on an
// auxetic plate lifted off a sphere, §0zt). Both are unfit: true,
// and take_step solves them again. The steps of ordinary runs never miss
// twice in a row, never stop at the limit, are never worse than none, and
// never tighten.
bool NewtonSolve::check_step(const real* Sdu, bool hit_limit) {
  const ReducedSystem::View V = L.view();
  const real *dU = du.data(), *Sk = L.known_product.data(), *rhs = L.rhs.data();
  const index np = p;
  const real missed = std::sqrt(S.sum(sum_over_entries("newton-step check", p, Cost{131, 20}, [=](index i) {
    real y0, y1, y2;
    reduced_rows(np, i, Sdu[i] - Sk[i], Sdu[np + i] - Sk[np + i], Sdu[2 * np + i] - Sk[2 * np + i], dU, V, y0, y1, y2);
    const real d0 = V.free[i] ? y0 - rhs[i] : 0, d1 = V.free[np + i] ? y1 - rhs[np + i] : 0,
               d2 = V.free[2 * np + i] ? y2 - rhs[2 * np + i] : 0;
    return d0 * d0 + d1 * d1 + d2 * d2;
  })));
  // (a factor > 1 where the step left more than a tenth of r_F, else 0)
  const real factor =
      missed > std::max(real(0.1) * step_rhs, step_target) && step_target > 0 ? missed / step_target : 0;
  // (a step stopped at the limit: the factor by which it fell short of its
  // target, at least kStallTightening)
  const real short_by =
      hit_limit && missed > step_target && step_target > 0 ? std::max(missed / step_target, kStallTightening) : 0;
  // (a step whose residual exceeds r_F itself: worse than no step at all)
  const bool worse = factor > 0 && missed > step_rhs;
  const real by = std::max({last_missed > 0 ? std::min(factor, last_missed) : real(0), short_by, worse ? factor : 0});
  if (by > 0) {
    const real tighter = std::min(work.tightening * by, real(1e8));
    // r's increments so far were that much less accurate than counted: its
    // error bound grows alike, so that r is refreshed before it is believed
    r_err *= tighter / work.tightening;
    work.tightening = tighter;
  }
  last_missed = factor;
  return worse || short_by > 0;
}

NewtonResult NewtonSolve::run() {
  if (!start()) return finish(NewtonReason::inner_failure);
  for (int k = 0;; ++k) {
    if (!measure(k)) return finish(NewtonReason::inner_failure);
    if (const auto stop = record(k)) return finish(*stop);
    redos = 0;
    do {  // (again where take_step asks to redo the step: x is unchanged)
      redo = false;
      step_tightening = work.tightening;
      if (const auto failed = newton_step()) return finish(*failed);
      if (const auto failed = take_step()) return finish(*failed);
    } while (redo);
    R.iterations = k + 1;
  }
}

}  // namespace

void ContactConditions::set_coulomb_bound(real F, const std::vector<real>& lambda) {
  HostLaunches host;  // (host values)
  coulomb_bound(index(phi.size()), F, lambda.data(), phi.data());
}

NewtonResult semismooth_newton(const SteklovPoincare& S, const ContactConditions& given, const NewtonOptions& opt) {
  return NewtonSolve(S, given, opt).run();
}

}  // namespace tresca
