// The matrix-free semismooth* Newton solver against a dense reference
// implementation of method.md §4 written here: the paper's full 4p system
// (G A + H) Δ = (G + H) v̂ with A built from a dense Schur complement, solved
// by LU, no reduction. Plus the KKT conditions, thread independence and the
// paper's Table 1 mesh sizes.
#include <gtest/gtest.h>
#include <array>
#include <cmath>
#include <cstdio>
#include <omp.h>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>

#include "core/contact/boundary_preconditioner.hpp"
#include "core/contact/report.hpp"
#include "kernels/contact_maps.hpp"
#include "core/contact/run.hpp"
#include "dense_reference.hpp"
#include "test_helpers.hpp"

namespace tresca {

namespace {

struct DenseNewton {
  std::vector<real> history;
  std::vector<Eigen::VectorXd> iterates;  // x_0 .. x_final, node-major (u_x, u_y, u_z, lambda)
  Eigen::VectorXd x;
  int iterations = 0;
};

// Dense semismooth* Newton (paper Section 4) in node-major ordering x^i = (u_τ, u_ν, λ).
// gap g: non-penetration u_z + g >= 0, i.e. F_4 = u_z + g.
// scale (empty: the paper's step): the approximation step in the metric
// W = diag(1/s, 1/s, 1, s) per node, i.e. problems (i)–(iii) minimise
// ½ vᵀW⁻¹v + ⟨F, v⟩ (+ φ|x_12 + v|); then ŷ = −W⁻¹v̂ and the Newton step is
// (G A + H) Δ = (G W⁻¹ + H) v̂ (with W = I the paper's (G + H) v̂). The
// stopping rule is the paper's |v̂| (W = I) either way.
// Coulomb (coulomb_F >= 0, phis unused): the bound is F x_4 — F max(0, λ)
// for v̂, F d_4 at the step's point, whose friction force F d_4 t moves with
// x_4: the sliding rows of H gain F t in the λ column.
// Stopping quantity: the paper's |v̂| (units empty) or the residual in
// consistent units |w| = |(s v_12, v_3, v_4)| of the step at the stiffness
// `units` (contact_maps.hpp). A node on the kink (λ − s (u_z + g) = 0) is in
// contact.
DenseNewton dense_newton(const Eigen::MatrixXd& S, const Eigen::VectorXd& bt, const std::vector<real>& phis, real gap,
                         const std::vector<real>& scale, real eps, int maxit, real coulomb_F = -1,
                         const std::vector<real>& units = {}, bool kink_contact = true) {
  const index p = S.rows() / 3, n = 4 * p;
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(n);
  for (index i = 0; i < p; ++i) {
    for (index j = 0; j < p; ++j)
      for (int a = 0; a < 3; ++a)
        for (int c = 0; c < 3; ++c) A(4 * i + a, 4 * j + c) = S(a * p + i, c * p + j);
    A(4 * i + 2, 4 * i + 3) = -1;  // F_3 = (S u − b̃)_z − λ
    A(4 * i + 3, 4 * i + 2) = 1;   // F_4 = u_z + g
    b[4 * i + 3] = -gap;
    for (int a = 0; a < 3; ++a) b[4 * i + a] = bt[a * p + i];
  }
  // problems (i)–(iii) at node i in the metric with stiffness s: v (4) of x
  // the bound of node i: given, or Coulomb's F max(0, lambda) at the
  // current x (v̂) or at the step's own pressure d_4 (the scaled step)
  auto approximation = [&](const Eigen::VectorXd& x, const Eigen::VectorXd& F, index i, real s, real* v, bool at_step) {
    // (iii) min v²/(2s) + F_4 v  over x_4 + v >= 0
    v[3] = std::max(-s * F[4 * i + 3], -x[4 * i + 3]);
    const real pressure = at_step ? x[4 * i + 3] + v[3] : x[4 * i + 3];
    const real phi = coulomb_F < 0 ? phis[i] : coulomb_F * std::max(real(0), pressure);
    const Eigen::Vector2d x12(x[4 * i], x[4 * i + 1]);
    // (i) min (s/2)|v|² + <F_12, v> + phi |x_12 + v|: prox of (phi/s)|.| at x_12 − F_12/s
    const Eigen::Vector2d z = x12 - Eigen::Vector2d(F[4 * i], F[4 * i + 1]) / s;
    const Eigen::Vector2d d12 =
        z.norm() > phi / s ? Eigen::Vector2d((1 - phi / (s * z.norm())) * z) : Eigen::Vector2d::Zero();
    v[0] = d12[0] - x12[0];
    v[1] = d12[1] - x12[1];
    // (ii) min ½v² + F_3 v
    v[2] = -F[4 * i + 2];
    return phi;
  };
  DenseNewton R;
  R.x = Eigen::VectorXd::Zero(n);
  for (int k = 0; k <= maxit; ++k) {
    const Eigen::VectorXd F = A * R.x - b;
    Eigen::VectorXd vhat(n), v(n), w(n), Winv = Eigen::VectorXd::Ones(n);
    Eigen::MatrixXd G = Eigen::MatrixXd::Zero(n, n), H = Eigen::MatrixXd::Zero(n, n);
    for (index i = 0; i < p; ++i) {
      const real s = scale.empty() ? 1 : scale[i];
      approximation(R.x, F, i, 1, &vhat[4 * i], false);
      const real phi = approximation(R.x, F, i, s, &v[4 * i], true);
      if (!units.empty()) {
        approximation(R.x, F, i, units[i], &w[4 * i], false);
        w[4 * i] *= units[i];
        w[4 * i + 1] *= units[i];
      }
      const real c = R.x[4 * i + 3] - s * F[4 * i + 3];
      const bool contact = kink_contact ? c >= 0 : c > 0;
      Winv.segment<4>(4 * i) << s, s, 1, 1 / s;
      const Eigen::Vector2d d12 = R.x.segment<2>(4 * i) + v.segment<2>(4 * i);
      if (d12.norm() == 0) {
        H.block<2, 2>(4 * i, 4 * i).setIdentity();
      } else {
        G.block<2, 2>(4 * i, 4 * i).setIdentity();
        const real c = phi / std::pow(d12.norm(), 3);
        H(4 * i, 4 * i) = c * d12[1] * d12[1];
        H(4 * i, 4 * i + 1) = H(4 * i + 1, 4 * i) = -c * d12[0] * d12[1];
        H(4 * i + 1, 4 * i + 1) = c * d12[0] * d12[0];
        if (coulomb_F >= 0 && contact) {  // the friction force F x_4 t moves with x_4
          H(4 * i, 4 * i + 3) = coulomb_F * d12[0] / d12.norm();
          H(4 * i + 1, 4 * i + 3) = coulomb_F * d12[1] / d12.norm();
        }
      }
      G(4 * i + 2, 4 * i + 2) = 1;
      if (contact)
        G(4 * i + 3, 4 * i + 3) = 1;
      else
        H(4 * i + 3, 4 * i + 3) = 1;
    }
    const real stop = units.empty() ? vhat.norm() : w.norm();
    R.history.push_back(stop);
    R.iterates.push_back(R.x);
    if (stop <= eps || k == maxit) break;
    // rows mix N/m with plain numbers: far from the solution LU alone was
    // off by 1e-7 relative (Coulomb, 12x6x6, F = 1.2: 3-7 N of 1e7 N in
    // lambda); one step of iterative refinement removes it
    const Eigen::MatrixXd M = G * A + H;
    const Eigen::VectorXd rhs = (G * Winv.asDiagonal() + H) * v;
    const Eigen::PartialPivLU<Eigen::MatrixXd> lu(M);
    Eigen::VectorXd delta = lu.solve(rhs);
    const Eigen::VectorXd d1 = lu.solve(rhs - M * delta);
    delta += d1;
    R.x += delta;
    R.iterations = k + 1;
  }
  return R;
}

// max-norm errors of (u, lambda) of a matrix-free iterate against a dense one
std::pair<real, real> iterate_errors(const std::vector<real>& u, const std::vector<real>& lam, const Eigen::VectorXd& x,
                                     real& umax, real& lmax) {
  const index p = index(lam.size());
  real uerr = 0, lerr = 0;
  umax = lmax = 0;
  for (index i = 0; i < p; ++i) {
    for (int a = 0; a < 3; ++a) {
      uerr = std::max(uerr, std::abs(u[a * p + i] - x[4 * i + a]));
      umax = std::max(umax, std::abs(x[4 * i + a]));
    }
    lerr = std::max(lerr, std::abs(lam[i] - x[4 * i + 3]));
    lmax = std::max(lmax, std::abs(x[4 * i + 3]));
  }
  return {uerr, lerr};
}

// Prints both |v̂| histories, then checks the Newton map: from every dense
// iterate x_k one matrix-free step of `method` with near-exact solves gives
// x_{k+1}. Steps are inexact by design (outer Krylov to an absolute target,
// inner solves relaxed as it converges); measured worst step error: 2.4e-9
// with a double-precision V-cycle, 1.1e-8 with the single-precision one
// (the default).
void expect_dense_steps(const SteklovPoincare& S, const DenseSchur& D, const DenseNewton& ref,
                        const ContactConditions& law, const NewtonOptions& method, const NewtonResult& run) {
  std::printf("dense  |v|:");
  for (real h : ref.history) std::printf(" %.3e", h);
  std::printf("\nmatrix-free |v|:");
  for (real h : run.history) std::printf(" %.3e", h);
  std::printf("\n");
  const index p = S.size() / 3;
  for (int k = 0; k + 1 < int(ref.iterates.size()); ++k) {
    std::vector<real> u0(3 * p), l0(p);
    for (index i = 0; i < p; ++i) {
      for (int a = 0; a < 3; ++a) u0[a * p + i] = ref.iterates[k][4 * i + a];
      l0[i] = ref.iterates[k][4 * i + 3];
    }
    NewtonOptions no = method;
    no.forcing_max = 1e-10;
    no.max_iterations = 1;
    no.line_search = false;  // the Newton map itself
    no.u0 = &u0;
    no.lambda0 = &l0;
    no.force_scale = D.b.norm();
    const NewtonResult step = semismooth_newton(S, law, no);
    EXPECT_NEAR(step.history[0], ref.history[k], 1e-8 * ref.history[k] + 1e-12 * ref.history[0]) << "k=" << k;
    real umax, lmax;
    const auto e = iterate_errors(step.u, step.lambda, ref.iterates[k + 1], umax, lmax);
    // (the paper's metric: 5e-8 measured where its path wanders, 1e-8 elsewhere)
    EXPECT_LE(e.first, 5e-8 * umax) << "u after step " << k + 1;
    EXPECT_LE(e.second, 2e-8 * lmax) << "lambda after step " << k + 1;
  }
}

// Runs both solvers; checks (a) the Newton map: from every dense iterate x_k
// one matrix-free step gives x_{k+1}; (b) the final solutions agree; (c) KKT.
// phi_of(i): the Tresca bound of contact node i
template <class PhiOf>
void compare_with_dense(const NewtonOptions& method, index ex, index ey, index ez, PhiOf phi_of, bool expect_mixed,
                        bool same_path, real gap = 0) {
  ProblemSpec spec = spec_for_dims(ex, ey, ez);
  RunOptions o;
  o.newton = method;
  o.nested = false;  // from x0 = 0, as the dense reference (12x6x6 has a coarser mesh)
  o.recover_interior = false;
  o.contact = ContactConditions::uniform(spec.contact_nodes(), 0, gap);
  for (index i = 0; i < spec.contact_nodes(); ++i) o.contact.phi[i] = phi_of(i);
  const std::vector<real>& phi = o.contact.phi;
  const RunResult R = run_tresca(spec, o);
  EXPECT_TRUE(R.contact.phi == phi);
  ASSERT_TRUE(R.newton.converged()) << to_string(R.newton.reason);
  const DenseSchur D = dense_schur(*R.problem);
  SteklovPoincare S(*R.problem);
  const std::vector<real> scale = method.scaling == StepScaling::diagonal ? step_scale(S) : std::vector<real>{};
  const std::vector<real> units = method.stop == StopRule::consistent ? step_scale(S) : std::vector<real>{};
  const DenseNewton ref = dense_newton(D.S, D.b, phi, gap, scale, 1e-6, 60, -1, units, method.kink_contact);
  ASSERT_LE(ref.history.back(), 1e-6) << "dense reference did not converge";
  const index p = R.problem->contact_nodes();
  // (a) the Newton map, step by step from the reference iterates, with
  // near-exact steps (the default forcing makes early steps inexact on purpose)
  expect_dense_steps(S, D, ref, o.contact, method, R.newton);
  // (b) whole runs: the same number of Newton steps as the exact-step method
  // where no node decision is marginal; with near-exact steps the same |v̂|
  // too; with the default forcing, a superlinear end: the last ratio
  // |v̂_k+1|/|v̂_k| above the floor of the step accuracy (0.1 eps) is < 1e-3
  // (a fixed step accuracy gave 1e-2 to 1e-3 per step, and rises)
  if (same_path) {
    EXPECT_EQ(R.newton.iterations, ref.iterations);
    if (method.forcing_max <= 1e-8) {
      for (size_t k = 0; k < std::min(R.newton.history.size(), ref.history.size()); ++k)
        if (ref.history[k] > 1e-6 * ref.history[0]) {
          EXPECT_NEAR(R.newton.history[k], ref.history[k], 1e-6 * ref.history[k]) << "k=" << k;
        }
    } else {
      const std::vector<real>& h = R.newton.history;
      real last = -1;
      for (size_t k = 0; k + 1 < h.size(); ++k)
        if (h[k + 1] > 10 * method.eps) last = h[k + 1] / h[k];
      EXPECT_GT(last, 0) << "no step above the floor";
      EXPECT_LT(last, 1e-3);
    }
  }
  real umax, lmax;
  const auto e = iterate_errors(R.newton.u, R.newton.lambda, ref.x, umax, lmax);
  EXPECT_LT(e.first, 1e-8 * umax);
  EXPECT_LT(e.second, 1e-8 * lmax);
  // (c) what the report prints, against the dense solution
  const FinalReport& F = R.report;
  real lsum = 0, ux_min = INFINITY, uz_max = -INFINITY;
  for (index i = 0; i < p; ++i) {
    lsum += ref.x[4 * i + 3];
    ux_min = std::min(ux_min, real(ref.x[4 * i]));
    uz_max = std::max(uz_max, real(ref.x[4 * i + 2]));
  }
  EXPECT_NEAR(F.lambda_sum, lsum, 1e-8 * std::abs(lsum));
  EXPECT_NEAR(F.ux_min, ux_min, 1e-8 * umax);
  EXPECT_NEAR(F.uz_max, uz_max, 1e-8 * umax);
  // (d) KKT at the solution (forces ~1e7 N, displacements ~0.1 m)
  if (expect_mixed) {  // every branch of the step: friction bits on any node (Tresca's law does not need contact)
    index slide_bits = 0;
    for (index i = 0; i < p; ++i) slide_bits += (F.status[i] & kStick) ? 0 : 1;
    EXPECT_GT(F.active, 0);
    EXPECT_GT(F.separated, 0);
    EXPECT_GT(F.sticking, 0);
    EXPECT_GT(slide_bits, 0);
  }
  const real fscale = F.btilde_norm;
  // |b̃|: Newton's first residual from x0 = 0
  EXPECT_NEAR(fscale, D.b.norm(), 1e-3 * D.b.norm());
  // Newton's residual r = S u - b̃ (loose at first, refreshed and kept by
  // increments) against the final check's tight one and the dense S u - b̃
  Eigen::VectorXd uc(3 * p);
  for (index i = 0; i < 3 * p; ++i) uc[i] = R.newton.u[i];
  const Eigen::VectorXd rd = D.S * uc - D.b;
  EXPECT_LT(test::max_abs_diff(R.newton.r, F.r), 1e-10 * fscale);
  for (index i = 0; i < 3 * p; ++i) EXPECT_NEAR(F.r[i], rd[i], 1e-9 * fscale) << "i=" << i;
  // every KKT field of the report, recomputed here from the dense r
  {
    real eq = 0, pen = 0, neg = 0, comp = 0, bound = 0, dir = 0, slip = 0;
    for (index i = 0; i < p; ++i) {
      const real ux = R.newton.u[i], uy = R.newton.u[p + i], uz = R.newton.u[2 * p + i], lam = R.newton.lambda[i];
      const real ut = std::hypot(ux, uy), s = R.newton.units[i];
      eq = std::max(eq, std::abs(rd[2 * p + i] - lam));
      pen = std::max(pen, -(uz + gap));
      neg = std::max(neg, -lam);
      comp = std::max(comp, std::abs(lam * (uz + gap)));
      bound = std::max(bound, std::hypot(rd[i], rd[p + i]) - phi[i]);
      if (F.status[i] & kStick)
        slip = std::max(slip, ut);
      else if (s * ut > F.tolerance)
        dir = std::max(dir, std::hypot(rd[i] + phi[i] * ux / ut, rd[p + i] + phi[i] * uy / ut));
    }
    const real f = 2e-9 * fscale;
    EXPECT_NEAR(F.equilibrium, eq, f);
    EXPECT_NEAR(F.uz_violation, std::max(pen, real(0)), 1e-15);
    EXPECT_NEAR(F.lambda_violation, std::max(neg, real(0)), f);
    EXPECT_NEAR(F.complementarity, comp, f * umax);
    EXPECT_NEAR(F.friction_bound, std::max(bound, real(0)), f);
    EXPECT_NEAR(F.friction_direction, dir, f + 1e-6 * dir);
    EXPECT_EQ(F.stick_slip, slip);
  }
  EXPECT_LT(F.equilibrium, 1e-10 * fscale);
  EXPECT_LT(F.uz_violation, 1e-12);
  EXPECT_LT(F.lambda_violation, 1e-10 * fscale);
  EXPECT_LT(F.complementarity, 1e-10 * fscale);
  EXPECT_LT(F.friction_bound, 1e-10 * fscale);
  // friction direction on every sliding node: r_τ = −φ_i u_τ/|u_τ|. The
  // direction of a slip |u_τ| is known only to δu/|u_τ| (δu = 1e-10 umax, the
  // solution's displacement accuracy), so the bound grows as φ_i δu/|u_τ|
  // for small slips (with φ_i = 7.5e6 N a 0.57 mm slip allows 0.4 N).
  // The paper's rule (|v̂| adds metres to newtons) may stop before the slip
  // directions are resolved: then the run must not call itself converged
  if (method.stop == StopRule::paper && !R.report.kkt_ok) {
    EXPECT_FALSE(R.converged());
    EXPECT_EQ(R.reason(), "kkt_check_failed");
    return;
  }
  EXPECT_TRUE(R.converged()) << R.reason();
  for (index i = 0; i < p; ++i) {
    if (F.status[i] & kStick) continue;
    const real ux = R.newton.u[i], uy = R.newton.u[p + i], ut = std::hypot(ux, uy);
    if (ut == 0) continue;
    const real dir = std::hypot(F.r[i] + phi[i] * ux / ut, F.r[p + i] + phi[i] * uy / ut);
    EXPECT_LE(dir, 1e-10 * fscale + phi[i] * 1e-10 * umax / ut) << "node " << i << " slip " << ut;
  }
  EXPECT_EQ(F.stick_slip, 0.0);
  EXPECT_LT(F.true_residual_relative, 1e-10);
}

// a whole run on the 12x6x6 mesh from x0 = 0 (Newton's own path, whose
// ratios and steps these tests read; the default would start from its
// coarser 6x3x3 mesh), contact values only
RunResult solve_12x6x6(real phi, real E = ProblemSpec{}.E) {
  ProblemSpec spec = spec_for_dims(12, 6, 6);
  spec.phi = phi;
  spec.E = E;
  RunOptions o;
  o.nested = false;
  o.recover_interior = false;
  return run_tresca(spec, o);
}

}  // namespace

real uniform(real phi, index) { return phi; }

// The paper's unscaled step with near-exact Newton steps
TEST(PaperStep, MatchesDenseReferenceAtPaperFriction) {
  compare_with_dense(NewtonOptions::paper_method(), 8, 4, 4, [](index i) { return uniform(1.0, i); }, false, true);
}

TEST(PaperStep, MatchesDenseReferenceWithStickSlipAndSeparation) {
  compare_with_dense(NewtonOptions::paper_method(), 8, 4, 4, [](index i) { return uniform(1e7, i); }, true, false);
}

// The default: approximation step scaled by diag(K_cc), inexact Newton steps
// with forcing terms; same iteration counts as the dense exact-step method
TEST(SemismoothNewton, MatchesDenseReferenceAtPaperFriction) {
  compare_with_dense({}, 8, 4, 4, [](index i) { return uniform(1.0, i); }, false, true);
}

TEST(SemismoothNewton, MatchesDenseReferenceWithStickSlipAndSeparation) {
  compare_with_dense({}, 8, 4, 4, [](index i) { return uniform(1e7, i); }, true, true);
}

TEST(SemismoothNewton, MatchesDenseReferenceOnOddMesh) {
  compare_with_dense({}, 7, 3, 3, [](index i) { return uniform(3e6, i); }, false, true);
}

TEST(SemismoothNewton, MatchesDenseReferenceWithABoundPerNode) {
  // Tresca with phi_i per contact node (issue 10): bounds from 0 to 3e7 N in
  // a pattern that makes neighbours stick and slide
  compare_with_dense({}, 8, 4, 4, [](index i) { return real((i * 7) % 5) * 7.5e6; }, true, true);
}

TEST(SemismoothNewton, MatchesDenseReferenceWithAGap) {
  // the rigid plane 5 cm below the contact face: u_z >= -0.05 m; nodes stick,
  // slide and separate
  // (the line search halves the first step, which would cross the gap, and
  // saves a step: not the dense reference's path, same solution)
  compare_with_dense({}, 8, 4, 4, [](index i) { return uniform(1e7, i); }, true, false, 0.05);
}

TEST(SemismoothNewton, FallsThroughASmallGapAndReachesTheDenseSolution) {
  // the benchmark (phi = 1) on 16x8x8 with the plane 1 micrometre below
  // the face: from x0 = 0 every node is separated, and the first step falls
  // freely through the plane by centimetres, which raises |w| by the
  // penetration times the stiffness for every step length down to 2^-10.
  // On |w| alone (envelope_merit off) the watchdog takes it whole and the
  // next step puts the nodes on the plane, as the dense reference's full
  // steps do (before the watchdog: stagnation at the first step, for gaps
  // from 1e-20 to about 1e-4 m; on 8x4x4 and 12x6x6 a halved first step
  // still decreased |w|). The energy's envelope falls along a short part of
  // that step (RESULTS.md §0zs), which it takes instead, no watchdog needed.
  // Both reach the dense reference's solution in a few steps.
  const real gap = 1e-6;
  ProblemSpec spec = spec_for_dims(16, 8, 8);
  spec.obstacle.gap = gap;
  for (bool envelope : {false, true}) {
    SCOPED_TRACE(envelope ? "envelope and |w|" : "|w| alone");
    RunOptions o;
    o.recover_interior = false;
    o.nested = false;
    o.newton.envelope_merit = envelope;
    const RunResult R = run_tresca(spec, o);
    ASSERT_TRUE(R.converged()) << R.reason();
    if (envelope) {
      EXPECT_EQ(R.newton.watchdog_steps, 0);
      EXPECT_GE(R.newton.envelope_steps, 1);  // (the first step's length at least)
      EXPECT_LT(R.newton.step_lengths.front(), 0.1);
    } else {
      EXPECT_EQ(R.newton.envelope_steps, 0);
      EXPECT_EQ(R.newton.watchdog_steps, 1);
      EXPECT_EQ(R.newton.step_lengths.front(), 1.0);
      EXPECT_GT(R.newton.merit[1], 10 * R.newton.merit[0]);  // the step no length of which decreased |w|
    }
    EXPECT_LE(R.newton.iterations, 5);
    const index p = R.problem->contact_nodes();
    EXPECT_EQ(R.report.active, p);  // every node on the plane, none below it
    EXPECT_LT(R.report.uz_violation, 1e-12);
    // the dense reference (full steps, exact solves) reaches the same solution
    const DenseSchur D = dense_schur(*R.problem);
    SteklovPoincare S(*R.problem);
    const std::vector<real> s = step_scale(S);
    const DenseNewton ref = dense_newton(D.S, D.b, R.contact.phi, gap, s, 1e-6, 60, -1, s);
    ASSERT_LE(ref.history.back(), 1e-6) << "dense reference did not converge";
    real umax, lmax;
    const auto e = iterate_errors(R.newton.u, R.newton.lambda, ref.x, umax, lmax);
    EXPECT_LT(e.first, 1e-8 * umax);
    EXPECT_LT(e.second, 1e-8 * lmax);
    for (index i = 0; i < p; ++i) EXPECT_NEAR(R.newton.u[2 * p + i], -gap, 1e-9 * gap) << i;
  }
}

TEST(SemismoothNewton, AnAuxeticMaterialTightensTheInnerSolvesItsStepsNeed) {
  // nu = -0.99: the bulk modulus is 1/150 of the shear modulus, and
  // S = K_cc - K_ci K_ii^-1 K_ic is much smaller than its two terms, so the
  // inner solves' relative tolerance buys far less accuracy in an S
  // product. The steps left 10-40 % of their systems' right-hand sides
  // instead of eta = 1 %, and Newton converged linearly: 19 steps here
  // from x0 = 0 (16 on 12x6x6; stagnation on 23x12x12 and at level 9).
  // Each step is now checked with its fresh S du, and the inner solves
  // tightened by the factor two steps in a row missed (NewtonSolve::check_step)
  ProblemSpec spec = spec_for_dims(16, 8, 8);
  spec.nu = -0.99;
  RunOptions o;
  o.recover_interior = false;
  o.nested = false;
  const RunResult R = run_tresca(spec, o);
  ASSERT_TRUE(R.converged()) << R.reason();
  EXPECT_GT(R.newton.inner_tightening, 3);  // (12 when written)
  EXPECT_LE(R.newton.iterations, 14);       // (10 when written)
  // the dense reference (exact solves) reaches the same solution (to 1e-4
  // N, 1e-12 of its forces: the dense S of this material carries rounding
  // errors of its large terms, and stalls at 5e-6 N)
  const DenseSchur D = dense_schur(*R.problem);
  SteklovPoincare S(*R.problem);
  const std::vector<real> s = step_scale(S);
  const DenseNewton ref = dense_newton(D.S, D.b, R.contact.phi, 0, s, 1e-4, 60, -1, s);
  ASSERT_LE(ref.history.back(), 1e-4) << "dense reference did not converge";
  real umax, lmax;
  const auto e = iterate_errors(R.newton.u, R.newton.lambda, ref.x, umax, lmax);
  EXPECT_LT(e.first, 1e-8 * umax);
  EXPECT_LE(e.second, 1e-8 * lmax);
  // the benchmark's material: every step within its accuracy, nothing tightened
  spec.nu = ProblemSpec{}.nu;
  const RunResult B = run_tresca(spec, o);
  ASSERT_TRUE(B.converged()) << B.reason();
  EXPECT_EQ(B.newton.inner_tightening, 1);
}

TEST(SemismoothNewton, MatchesDenseReferenceWhereThePaperStepLosesThePath) {
  // 12x6x6, phi = 1e6: the paper's exact-step method takes 7 steps; its
  // inexact matrix-free twin parted from it at step 4 and took 9 (issue 9)
  compare_with_dense({}, 12, 6, 6, [](index i) { return uniform(1e6, i); }, false, true);
}

// The Coulomb Newton step (FrictionLaw::CoulombMethod::newton) against the dense
// 4p system with the friction force's λ column in H: from every dense
// iterate one matrix-free step (GMRES, near-exact) gives the next, and the
// whole runs reach the same solution where nodes stick, slide and separate.
TEST(SemismoothNewton, CoulombStepMatchesDenseReference) {
  const real F = 1.2;  // 12x6x6: 7 nodes separate, 7 stick, 70 slide
  const ProblemSpec spec = spec_for_dims(12, 6, 6);
  RunOptions o;
  o.recover_interior = false;
  o.friction = coulomb_friction(F, FrictionLaw::CoulombMethod::newton);
  const RunResult R = run_tresca(spec, o);
  ASSERT_TRUE(R.converged()) << R.reason();
  ASSERT_FALSE(R.coulomb_fallback);
  const index p = R.problem->contact_nodes();
  const DenseSchur D = dense_schur(*R.problem);
  SteklovPoincare S(*R.problem);
  const std::vector<real> scale = step_scale(S);
  const DenseNewton ref = dense_newton(D.S, D.b, {}, 0, scale, 1e-6, 60, F, scale);
  ASSERT_LE(ref.history.back(), 1e-6) << "dense reference did not converge";
  NewtonOptions method;
  method.friction = coulomb_friction(F, FrictionLaw::CoulombMethod::newton);
  expect_dense_steps(S, D, ref, ContactConditions::uniform(p, 0, 0), method, R.newton);
  real umax, lmax;
  const auto e = iterate_errors(R.newton.u, R.newton.lambda, ref.x, umax, lmax);
  EXPECT_LT(e.first, 1e-8 * umax);
  EXPECT_LT(e.second, 1e-8 * lmax);
  EXPECT_GT(R.report.sticking, 0);
  EXPECT_GT(R.report.sliding, 0);
  EXPECT_GT(R.report.separated, 0);
}

TEST(SemismoothNewton, ConvergesSuperlinearly) {
  // the ratios |w_k+1|/|w_k| fall step by step to the end (measured: 0.21,
  // 5.4e-3, 4.6e-5, then 2e-8 below the floor 10 eps)
  const RunResult R = solve_12x6x6(1e6);
  ASSERT_TRUE(R.newton.converged());
  const real eps = NewtonOptions{}.eps;
  const std::vector<real>& h = R.newton.history;
  ASSERT_GE(h.size(), 5u);
  std::vector<real> q;
  for (size_t k = 0; k + 1 < h.size() && h[k + 1] > 10 * eps; ++k) q.push_back(h[k + 1] / h[k]);
  ASSERT_GE(q.size(), 3u);
  for (size_t k = 1; k < q.size(); ++k) EXPECT_LT(q[k], 0.1 * q[k - 1]) << "ratio " << k;
  EXPECT_LT(q.back(), 1e-4);
}

TEST(SemismoothNewton, GapLargerThanTheFreeDisplacementGivesTheFreeElasticSolution) {
  // no friction, the plane 10 m below: nothing touches, lambda = 0, and the
  // contact face moves as the unconstrained body does: S u = b̃
  ProblemSpec spec = spec_for_dims(8, 4, 4);
  spec.phi = 0;
  spec.obstacle.gap = 10;
  RunOptions o;
  o.recover_interior = false;
  const RunResult R = run_tresca(spec, o);
  ASSERT_TRUE(R.newton.converged()) << to_string(R.newton.reason);
  const index p = R.problem->contact_nodes();
  EXPECT_EQ(R.report.active, 0);
  EXPECT_EQ(R.report.separated, p);
  for (index i = 0; i < p; ++i) EXPECT_EQ(R.newton.lambda[i], 0.0);
  const DenseSchur D = dense_schur(*R.problem);
  const Eigen::VectorXd ufree = D.S.ldlt().solve(D.b);
  real err = 0;
  for (index i = 0; i < 3 * p; ++i) err = std::max(err, std::abs(R.newton.u[i] - ufree[i]));
  EXPECT_LT(err, 1e-8 * ufree.cwiseAbs().maxCoeff());
  EXPECT_LT(ufree.minCoeff(), -1e-3);  // the free body does move down: the gap matters
}

TEST(SemismoothNewton, SingleAndDoublePrecisionVCyclesGiveTheSameSolution) {
  // the V-cycles only precondition double-precision Krylov solves: the
  // answers agree to the solver tolerances, in the stick/slip/separation regime
  ProblemSpec spec = spec_for_dims(12, 6, 6);
  spec.phi = 3e6;  // 56 in contact, 28 separated, 9 sticking, 75 sliding
  RunResult R[2];
  for (int k = 0; k < 2; ++k) {
    RunOptions o;
    o.recover_interior = false;
    o.mg.precision = k ? Precision::single_precision : Precision::double_precision;
    R[k] = run_tresca(spec, o);
    ASSERT_TRUE(R[k].newton.converged()) << to_string(R[k].newton.reason);
  }
  EXPECT_LE(std::abs(R[1].newton.iterations - R[0].newton.iterations), 1);
  EXPECT_EQ(R[0].report.active, R[1].report.active);
  EXPECT_EQ(R[0].report.sticking, R[1].report.sticking);
  EXPECT_GT(R[0].report.sticking, 0);
  EXPECT_GT(R[0].report.sliding, 0);
  EXPECT_GT(R[0].report.separated, 0);
  EXPECT_LT(test::max_abs_diff(R[0].newton.u, R[1].newton.u), 1e-8 * test::max_abs(R[0].newton.u));
  EXPECT_LT(test::max_abs_diff(R[0].newton.lambda, R[1].newton.lambda), 1e-8 * test::max_abs(R[0].newton.lambda));
  EXPECT_NEAR(R[0].report.lambda_sum, R[1].report.lambda_sum, 1e-10 * R[0].report.lambda_sum);
  EXPECT_LT(R[1].report.true_residual_relative, 1e-10);
}

TEST(SemismoothNewton, ResultsAgreeWithOneAndTwoThreads) {
  ProblemSpec spec = spec_for_level(5);
  spec.phi = 3e6;
  RunOptions o;
  o.recover_interior = false;
  const int keep = omp_get_max_threads();
  omp_set_num_threads(1);
  const RunResult a = run_tresca(spec, o);
  omp_set_num_threads(2);
  const RunResult b = run_tresca(spec, o);
  omp_set_num_threads(keep);
  ASSERT_TRUE(a.newton.converged());
  ASSERT_EQ(a.newton.iterations, b.newton.iterations);
  // bitwise: every reduction has a fixed order (vector_ops.hpp), every kernel
  // writes each output from one thread, so the thread count changes nothing
  EXPECT_TRUE(a.newton.u == b.newton.u);
  EXPECT_TRUE(a.newton.lambda == b.newton.lambda);
  EXPECT_TRUE(a.newton.history == b.newton.history);
  EXPECT_EQ(a.inner_iterations, b.inner_iterations);
}

// The approximation step (kernels/contact_maps.cpp) node by node against
// method.md §4's closed forms written out here, in the metric s per node
// (z = x_12 - r_12/s, d_12 = max(0, 1 - phi/(s|z|)) z, d_4 = max(0, x_4 -
// s x_3)), on a contact face large enough to run threaded: every pointer
// case (units, scale missing, given, the same array), nodes on the kink
// (x_4 - s x_3 = 0 exactly) and nodes with z = 0 (with phi = 0 too), and the
// same bits on 1, 2 and 3 threads (a vectorised loop with a scalar
// remainder must round each node the same wherever the shares cut).
TEST(ApproximationStep, MatchesTheClosedFormsOnEveryNodeAndIsTheSameOnAnyThreadCount) {
  const index p = 20011;
  std::vector<real> u = test::random_vector(3 * p, 11), lambda = test::random_vector(p, 12),
                    r = test::random_vector(3 * p, 13), phi = test::random_vector(p, 14),
                    gap = test::random_vector(p, 15), units = test::random_vector(p, 16),
                    scale = test::random_vector(p, 17);
  for (index i = 0; i < p; ++i) {
    phi[i] = 0.5 * (phi[i] + 1);      // [0, 1]
    gap[i] = 0.1 * gap[i];
    units[i] = 1.25 + 0.75 * units[i];  // [0.5, 2]
    scale[i] = 1.25 + 0.75 * scale[i];
    if (i % 7 == 0) u[2 * p + i] = gap[i] = lambda[i] = 0;  // on the kink: x_4 - s x_3 = 0
    if (i % 11 == 0) r[i] = u[i], r[p + i] = u[p + i];      // z = 0 at s = 1 ...
    if (i % 22 == 0) phi[i] = 0;                           // ... with phi = 0: 0/0
  }
  struct Step {
    real d1, d2, d4;
    bool contact, stick;
  };
  auto closed_form = [&](index i, real s, bool kink) {
    const real x3 = u[2 * p + i] + gap[i], z1 = u[i] - r[i] / s, z2 = u[p + i] - r[p + i] / s;
    const real nz = std::sqrt(z1 * z1 + z2 * z2);
    const real t = s * nz > phi[i] ? 1 - phi[i] / (s * nz) : 0;
    const real c = lambda[i] - s * x3;
    return Step{t * z1, t * z2, c > 0 ? c : 0, kink ? c >= 0 : c > 0, t == 0};
  };
  auto close = [](real a, real b) { return std::abs(a - b) <= 1e-14 * (1 + std::abs(b)); };
  const int keep = omp_get_max_threads();
  for (bool kink : {true, false})
    for (int pointers = 0; pointers < 4; ++pointers) {
      const real* su = pointers & 1 ? units.data() : nullptr;
      const real* ss = pointers == 3 ? units.data() : pointers & 2 ? scale.data() : nullptr;
      std::vector<std::vector<real>> v(3), w(3), d(3);
      std::vector<std::vector<std::uint8_t>> status(3);
      std::vector<ResidualNorms> norms(3);
      for (int t = 0; t < 3; ++t) {
        omp_set_num_threads(t + 1);
        v[t].assign(4 * p, 0);
        w[t].assign(4 * p, 0);
        d[t].assign(3 * p, 0);
        status[t].assign(p, 0);
        norms[t] = approximation_step(p, ContactLaw{phi.data(), gap.data(), kink}, ss, su, u.data(), lambda.data(),
                                      r.data(), v[t].data(), w[t].data(), d[t].data(), status[t].data());
      }
      omp_set_num_threads(keep);
      for (int t = 1; t < 3; ++t) {
        EXPECT_TRUE(v[t] == v[0] && w[t] == w[0] && d[t] == d[0] && status[t] == status[0]) << t + 1 << " threads";
        EXPECT_EQ(norms[t].paper, norms[0].paper);
        EXPECT_EQ(norms[t].consistent, norms[0].consistent);
      }
      int mismatches = 0;
      index kinks = 0, sticks = 0;
      for (index i = 0; i < p && mismatches < 5; ++i) {
        const real x1 = u[i], x2 = u[p + i], x4 = lambda[i];
        const Step paper = closed_form(i, 1, kink), unit = closed_form(i, su ? su[i] : 1, kink),
                   step = closed_form(i, ss ? ss[i] : 1, kink);
        const real s_u = su ? su[i] : 1;
        const bool ok =
            close(v[0][i], paper.d1 - x1) && close(v[0][p + i], paper.d2 - x2) &&
            v[0][2 * p + i] == -(r[2 * p + i] - x4) && close(v[0][3 * p + i], paper.d4 - x4) &&
            close(w[0][i], s_u * (unit.d1 - x1)) && close(w[0][p + i], s_u * (unit.d2 - x2)) &&
            w[0][2 * p + i] == v[0][2 * p + i] && close(w[0][3 * p + i], unit.d4 - x4) && close(d[0][i], step.d1) &&
            close(d[0][p + i], step.d2) && close(d[0][2 * p + i], step.d4) &&
            status[0][i] == ((step.contact ? kContact : 0) | (step.stick ? kStick : 0));
        if (!ok) ++mismatches;
        EXPECT_TRUE(ok) << "node " << i << " kink " << kink << " pointers " << pointers;
        kinks += lambda[i] == 0 && u[2 * p + i] == 0 && gap[i] == 0;
        sticks += step.stick;
      }
      EXPECT_GT(kinks, p / 8);
      EXPECT_GT(sticks, p / 12);  // (the z = 0 nodes at least, where the step's s is 1)
      real vv = 0;
      for (real x : v[0]) vv += x * x;
      EXPECT_NEAR(norms[0].paper, vv, 1e-12 * vv);
    }
}

TEST(EnvelopeChange, EqualsTheChangeOfEachNodesMinimumFoundByACompassSearch) {
  // Each node's envelope term is a minimum over y with y_z + g >= 0 of
  // q(y) = r·(y − u) + ½ s |y − u|² + phi |y_τ| (contact_maps.hpp). The
  // reference finds it without the closed form: a compass search on q (the
  // six axis directions and four diagonals of the tangential plane, halving
  // its step down to 1e-12 of the start, y_z clamped to the obstacle).
  // Nodes that stick (phi large), slide, are pressed onto the obstacle
  // (r_z large) or are free of it.
  const index p = 60;
  std::vector<real> u = test::random_vector(3 * p, 21), r = test::random_vector(3 * p, 22),
                    du = test::random_vector(3 * p, 23), Sdu = test::random_vector(3 * p, 24),
                    phi = test::random_vector(p, 25), gap = test::random_vector(p, 26), s = test::random_vector(p, 27);
  for (index i = 0; i < p; ++i) {
    phi[i] = (i % 3 == 0 ? 5 : 0.5) * (phi[i] + 1);  // every third node sticks
    gap[i] = 0.1 * (gap[i] + 1);
    s[i] = 1.25 + 0.75 * s[i];
    if (i % 4 == 0) r[2 * p + i] = 3 + r[2 * p + i];  // pressed onto the obstacle
  }
  auto minimum = [&](index i, real a) {
    real uu[3], rr[3];
    for (int c = 0; c < 3; ++c) uu[c] = u[c * p + i] + a * du[c * p + i], rr[c] = r[c * p + i] + a * Sdu[c * p + i];
    auto q = [&](const std::array<real, 3>& y) {
      real value = phi[i] * std::hypot(y[0], y[1]);
      for (int c = 0; c < 3; ++c) value += rr[c] * (y[c] - uu[c]) + 0.5 * s[i] * (y[c] - uu[c]) * (y[c] - uu[c]);
      return value;
    };
    std::array<real, 3> y{uu[0], uu[1], std::max(uu[2], -gap[i])};
    real best = q(y);
    const real h0 = 4;
    const real dirs[10][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1},
                              {0, 0, -1}, {1, 1, 0}, {1, -1, 0}, {-1, 1, 0}, {-1, -1, 0}};
    for (real h = h0; h > 1e-12 * h0;) {
      bool moved = false;
      for (const auto& d : dirs) {
        std::array<real, 3> z{y[0] + h * d[0], y[1] + h * d[1], std::max(y[2] + h * d[2], -gap[i])};
        const real value = q(z);
        if (value < best) best = value, y = z, moved = true;
      }
      if (!moved) h *= 0.5;
    }
    return best;
  };
  for (real a : {0.0, 0.3, 1.0}) {
    const EnvelopeChange e = envelope_change(p, ContactLaw{phi.data(), gap.data()}, s.data(), a, u.data(), r.data(),
                                             du.data(), Sdu.data());
    real change = 0, size = 0;
    for (index i = 0; i < p; ++i) {
      const real at_a = minimum(i, a), at_0 = minimum(i, 0);
      change += at_a - at_0;
      size += std::abs(at_a) + std::abs(at_0);
    }
    EXPECT_NEAR(e.change, change, 1e-9 * size) << "a = " << a;
    EXPECT_NEAR(e.size, size, 1e-9 * size) << "a = " << a;
    if (a == 0) EXPECT_EQ(e.change, 0);
    else EXPECT_GT(std::abs(e.change), 1e-3 * size) << "a = " << a;  // (a change the test can see)
  }
}

// Young's modulus from 2.1e9 to 1e16 Pa (issue 11: E >= 1e13 used to
// stagnate): with the diagonal metric the approximation step compares force
// with stiffness x displacement, so the Newton path does not depend on E:
// the same steps, contact and stick sets, E u and lambda, where nodes stick,
// slide and separate.
TEST(SemismoothNewton, TheDiagonalMetricMakesTheSolveIndependentOfYoungsModulus) {
  const RunResult ref = solve_12x6x6(3e6);
  const real E0 = ProblemSpec{}.E;
  ASSERT_TRUE(ref.converged()) << ref.reason();
  for (real E : {1e13, 1e16}) {
    const RunResult R = solve_12x6x6(3e6, E);
    ASSERT_TRUE(R.converged()) << "E = " << E << ": " << R.reason();
    EXPECT_EQ(R.newton.iterations, ref.newton.iterations) << "E = " << E;
    EXPECT_EQ(R.report.status, ref.report.status) << "E = " << E;
    const index p = R.problem->contact_nodes();
    const real umax = test::max_abs(ref.newton.u), lmax = test::max_abs(ref.newton.lambda);
    for (index i = 0; i < 3 * p; ++i)
      ASSERT_NEAR(R.newton.u[i] * E / E0, ref.newton.u[i], 1e-7 * umax) << "E = " << E << ", entry " << i;
    for (index i = 0; i < p; ++i) ASSERT_NEAR(R.newton.lambda[i], ref.newton.lambda[i], 1e-7 * lmax) << "E = " << E;
  }
}

TEST(SemismoothNewton, StagnationNeedsNoNewBestOverAWholeWindow) {
  // Coulomb F = 2 on 9x7x5 without a line search (issue 19): the merit
  // wanders for five steps, then converges fast; no new best by half over
  // 10 steps is the evidence of a floor
  const std::vector<real> wander = {6.5e7, 1.4e6, 4.7e7, 6.5e7, 4.4e7, 2.4e7, 8.0e6, 2.7e4, 1.0e1, 1e-3};
  for (size_t k = 1; k <= wander.size(); ++k)
    EXPECT_FALSE(stagnated(std::vector<real>(wander.begin(), wander.begin() + k), 10)) << "after step " << k - 1;
  std::vector<real> floor = {1e7, 1e2, 1e-2, 3e-4};
  for (int k = 0; k < 16; ++k) floor.push_back(k % 2 ? 2.5e-4 : 1.2e-4);
  EXPECT_FALSE(stagnated(std::vector<real>(floor.begin(), floor.begin() + 13), 10));
  EXPECT_TRUE(stagnated(floor, 10));
}

TEST(SemismoothNewton, ReportsIterationLimitHonestly) {
  ProblemSpec spec = spec_for_dims(8, 4, 4);
  RunOptions o;
  o.newton.max_iterations = 1;
  o.recover_interior = false;
  const RunResult R = run_tresca(spec, o);
  EXPECT_FALSE(R.newton.converged());
  EXPECT_FALSE(R.converged());
  EXPECT_EQ(R.newton.reason, NewtonReason::iteration_limit);
  EXPECT_EQ(R.newton.iterations, 1);
  EXPECT_EQ(R.newton.history.size(), 2u);
  EXPECT_GT(R.newton.history.back(), 1e-6);
}

TEST(SemismoothNewton, RejectsAnInitialStateWithoutItsScaleOrBody) {
  // an initial iterate needs |b̃| (the accuracies' scale); a given residual
  // needs the body it came from: clear errors, before any solve
  const Problem P = make_problem(spec_for_dims(8, 4, 4));
  const SteklovPoincare S(P);
  const index p = P.contact_nodes();
  const ContactConditions law = ContactConditions::uniform(p, 1, 0);
  const std::vector<real> u0(3 * p, 0.0), l0(p, 0.0), r0(3 * p, 1.0);
  Field<real> body(S.full_size(), 0.0);
  NewtonOptions o;
  o.u0 = &u0;
  o.lambda0 = &l0;
  EXPECT_THROW(semismooth_newton(S, law, o), std::invalid_argument);
  o.force_scale = 1e7;
  o.r0 = &r0;
  EXPECT_THROW(semismooth_newton(S, law, o), std::invalid_argument);
  o.body0 = &body;
  Field<real> short_body(7, 0.0);
  o.body0 = &short_body;
  EXPECT_THROW(semismooth_newton(S, law, o), std::invalid_argument);
}

TEST(SemismoothNewton, StopsAtWhatRResolvesForAnUnattainableTolerance) {
  // eps far below what r = S u - b~ resolves (forces ~1e7 N): |w| wanders
  // at its floor with the contact states settled (semismooth.cpp:
  // floor_stop); the run is converged to that level, confirmed by a fresh r
  // and by the final KKT check, and says so (NewtonResult::residual_floor)
  ProblemSpec spec = spec_for_dims(8, 4, 4);
  spec.phi = 3e6;  // (at phi = 1 the increments reach exact zeros)
  RunOptions o;
  o.newton.eps = 1e-20;
  o.newton.max_iterations = 100;
  o.recover_interior = false;
  const RunResult R = run_tresca(spec, o);
  const real b = R.newton.force_scale;
  EXPECT_TRUE(R.converged()) << R.reason();
  EXPECT_GE(R.newton.residual_floor, o.newton.residual_accuracy * b * (1 - 1e-12));  // what r resolves at best
  EXPECT_LE(R.newton.residual_floor, o.kkt_rtol * b);
  EXPECT_EQ(R.newton.tolerance, R.newton.residual_floor);
  EXPECT_LE(R.newton.history.back(), R.newton.residual_floor);
  EXPECT_LT(R.newton.iterations, 40);
  EXPECT_TRUE(R.report.kkt_ok);
  EXPECT_LT(R.report.true_residual_relative, 1e-12);  // the solution itself is fine
  // a floor above the one accepted: stagnation, as before floor_stop
  o.newton.floor_rtol = 1e-14;
  const RunResult F = run_tresca(spec, o);
  EXPECT_FALSE(F.newton.converged());
  EXPECT_EQ(F.newton.reason, NewtonReason::stagnation);
  EXPECT_EQ(F.newton.residual_floor, 0);
  EXPECT_LT(F.newton.iterations, 40);
  EXPECT_LT(F.report.true_residual_relative, 1e-12);
}

// The Newton step's preconditioner K + B shares the K_ii solver's smoother
// bounds (boundary_preconditioner.cpp): they must bound the Jacobi-scaled
// K with the contact face free, not just K_ii (then, with B, the larger of
// that and 2). On a mesh one element thick K's largest eigenvalue is half
// again K_ii's: its Chebyshev smoother, bounded by K_ii's, amplified the
// modes above, and the boundary CG broke down (tresca --dims 100x1x1:
// inner_solver_failure). Against a dense eigensolver on every smoothed
// level.
TEST(BoundaryPreconditioner, SharesSmootherBoundsThatHoldForKWithTheContactFaceFree) {
  for (const auto& dims : {std::array<index, 3>{40, 1, 1}, std::array<index, 3>{12, 6, 6}}) {
    const Problem P = make_problem(spec_for_dims(dims[0], dims[1], dims[2]));
    MGOptions mo;
    mo.coarse_nodes = 40;
    const SteklovPoincare S(P, mo);
    const Multigrid& mg = S.interior_multigrid();
    ASSERT_GE(mg.num_levels(), 2);
    real ratio_ii = 0;  // K's largest eigenvalue over K_ii's, on the finest grid
    for (int l = 0; l + 1 < mg.num_levels(); ++l) {
      const GridDims& g = mg.hierarchy()->levels[l].grid;
      auto largest = [&](unsigned faces) {
        return jacobi_scaled_lmax(ElasticityOperator(g, faces, P.spec.E, P.spec.nu));
      };
      const real free_face = largest(P.dirichlet_faces), interior = largest(P.interior_faces);
      EXPECT_GE(mg.lmax(l), free_face) << dims[0] << "x" << dims[1] << "x" << dims[2] << " level " << l;
      EXPECT_GE(free_face, interior * (1 - 1e-12));  // (interlacing)
      if (l == 0) ratio_ii = free_face / interior;
    }
    if (dims[1] == 1) {
      EXPECT_GT(ratio_ii, 1.3);  // (1.5 when written: the case that broke down)
    }
  }
  // and the run that broke down converges, its answer verified by its own KKT check
  const RunResult R = run_tresca(spec_for_dims(100, 1, 1), RunOptions{});
  EXPECT_TRUE(R.converged()) << R.reason();
}

TEST(BoundaryPreconditioner, KeepsOuterIterationsFlatUnderRefinement) {
  double per_step[3];
  const int levels[3] = {4, 6, 7};
  for (int k = 0; k < 3; ++k) {
    RunOptions o;
    o.recover_interior = false;
    const RunResult R = run_tresca(spec_for_level(levels[k]), o);
    ASSERT_TRUE(R.newton.converged());
    EXPECT_EQ(R.newton.outer_limit_hits, 0);
    per_step[k] = double(R.newton.outer_iterations) / R.newton.iterations;
    EXPECT_LT(per_step[k], 6.0) << "level " << levels[k];
  }
  EXPECT_LE(per_step[2], per_step[0] + 1.0);
}

TEST(BoundaryPreconditioner, KeepsOuterIterationsBoundedWhereNodesStickSlideAndSeparate) {
  // phi = 3e6: the friction blocks H and the fixed-dof penalties are large
  // (at phi = 1 the friction block is negligible)
  double per_step[2];
  const int levels[2] = {4, 6};
  for (int k = 0; k < 2; ++k) {
    ProblemSpec spec = spec_for_level(levels[k]);
    spec.phi = 3e6;
    RunOptions o;
    o.recover_interior = false;
    const RunResult R = run_tresca(spec, o);
    ASSERT_TRUE(R.newton.converged());
    ASSERT_GT(R.report.sticking, 0);
    ASSERT_GT(R.report.separated, 0);
    EXPECT_EQ(R.newton.outer_limit_hits, 0);
    per_step[k] = double(R.newton.outer_iterations) / R.newton.iterations;
    EXPECT_LT(per_step[k], 10.0) << "level " << levels[k];
  }
  EXPECT_LE(per_step[1], per_step[0] + 2.0);
}

TEST(BoundaryPreconditioner, IsSymmetricOnTheFreeDofs) {
  // CG needs M symmetric: |x^T M y - y^T M x| small relative to |x||M y|
  const Problem P = make_problem(spec_for_dims(12, 6, 6));
  for (Precision prec : {Precision::double_precision, Precision::single_precision}) {
    MGOptions mo;
    mo.precision = prec;
    const SteklovPoincare S(P, mo);
    BoundaryPreconditioner M(S, mo);
    const index p = P.contact_nodes(), n = 3 * p;
    Field<real> h(n, 0.0);
    Field<std::uint8_t> fixed(n, 0), free(n, 1);
    for (index i = 0; i < p; ++i) {
      if (i % 3 == 0) fixed[i] = fixed[p + i] = 1, free[i] = free[p + i] = 0;  // sticking
      else h[i] = 1e8, h[p + i] = -2e7, h[2 * p + i] = 3e8;                      // sliding: PSD block
      if (i % 2 == 0) fixed[2 * p + i] = 1, free[2 * p + i] = 0;                // in contact
    }
    M.update(h, fixed, free);
    auto x = test::random_vector(n, 31), y = test::random_vector(n, 32);
    for (index i = 0; i < n; ++i)
      if (!free[i]) x[i] = y[i] = 0;
    std::vector<real> Mx(n), My(n);
    M.apply(x.data(), Mx.data());
    M.apply(y.data(), My.data());
    real a = 0, b = 0, nx = 0, nmy = 0;
    for (index i = 0; i < n; ++i) {
      a += x[i] * My[i];
      b += y[i] * Mx[i];
      nx += x[i] * x[i];
      nmy += My[i] * My[i];
    }
    EXPECT_LT(std::abs(a - b), (prec == Precision::single_precision ? 1e-5 : 1e-12) * std::sqrt(nx * nmy))
        << to_string(prec);
  }
}

TEST(Problem, MeshSizesMatchPaperTable1) {
  const long long n[] = {225, 637, 1377, 4056, 9537, 27072, 70785};
  const long long p[] = {40, 84, 144, 299, 544, 1104, 2112};
  for (int level = 2; level <= 8; ++level) {
    const Problem P = make_problem(spec_for_level(level));
    EXPECT_EQ(P.nodes(), n[level - 2]) << "level " << level;
    EXPECT_EQ(P.contact_nodes(), p[level - 2]) << "level " << level;
  }
  const Problem P1 = make_problem(spec_for_level(1));
  EXPECT_EQ(P1.nodes(), 112);  // method.md §1: the formula's level 1 (the paper repeats level 2)
  EXPECT_EQ(P1.contact_nodes(), 24);
}

}  // namespace tresca

namespace tresca {
// Issue 19, item 2: 9x7x5, phi = 5e6, E = 7e10, nu = 0.33 in the paper's
// metric. The paper's rule |v̂| <= 1e-6 (metres added to newtons) stopped
// after 7 steps with u 1.3e-5 off and a slip direction 1e4 N off while the
// run said "converged". The consistent rule |w| [N] goes on to the
// solution; the literal paper method's "converged" is overruled by its own
// KKT check.
TEST(SemismoothNewton, ConvergedMeansItsOwnKKTCheckAgrees) {
  ProblemSpec spec = spec_for_dims(9, 7, 5);
  spec.phi = 5e6;
  spec.E = 7e10;
  spec.nu = 0.33;
  RunOptions o;
  o.recover_interior = false;
  o.nested = false;
  const RunResult ref = run_tresca(spec, o);  // the default: diagonal metric
  ASSERT_TRUE(ref.converged()) << ref.reason();
  o.newton.scaling = StepScaling::paper;  // --scaling paper
  o.newton.forcing_max = NewtonOptions::paper_method().forcing_max;
  const RunResult R = run_tresca(spec, o);
  ASSERT_TRUE(R.converged()) << R.reason();
  EXPECT_TRUE(R.report.kkt_ok);
  EXPECT_LE(R.report.friction_direction, R.report.tolerance);
  EXPECT_LE(R.report.kkt_force, R.report.tolerance);
  const real umax = test::max_abs(ref.newton.u);
  EXPECT_LT(test::max_abs_diff(R.newton.u, ref.newton.u), 1e-9 * umax);
  EXPECT_LT(test::max_abs_diff(R.newton.lambda, ref.newton.lambda), 1e-9 * test::max_abs(ref.newton.lambda));
  // the literal method (--table): its rule says converged, its check does not
  o.newton = NewtonOptions::paper_method();
  const RunResult P = run_tresca(spec, o);
  EXPECT_TRUE(P.newton.converged());
  EXPECT_FALSE(P.report.kkt_ok);
  EXPECT_GT(P.report.friction_direction, P.report.tolerance);
  EXPECT_FALSE(P.converged());
  EXPECT_EQ(P.reason(), "kkt_check_failed");
  // (and its u is off by more than the two verified runs differ, 1e-9: where
  // it stops depends on its inexact path, 1e-7 umax when written, 2.3e-8
  // since the smoother's bounds hold for K + B, perf/RESULTS.md §0zd)
  EXPECT_GT(test::max_abs_diff(P.newton.u, ref.newton.u), 1e-8 * umax);
}
}  // namespace tresca

namespace tresca {
// Issue 19, item 5: the headline work figure (fine-grid matvec equivalents)
// against the solver's own counts: every S application is one inner solve of
// `its` iterations, costing its (1 + V-cycle) + 2/nz (steklov.cpp), so with
// no outer preconditioner the Newton work is inner_iterations (1 + cycle) +
// applications 2/nz. Dropping any application's count breaks it.
TEST(SemismoothNewton, CountedWorkIsTheCountedInnerSolves) {
  const Problem P = make_problem(spec_for_dims(12, 6, 6));
  const SteklovPoincare S(P);
  NewtonOptions o;
  o.outer_pc = OuterPreconditioner::none;
  const ContactConditions law = ContactConditions::uniform(P.contact_nodes(), 3e6, 0);
  const NewtonResult R = semismooth_newton(S, law, o);
  ASSERT_TRUE(R.converged());
  const double per_apply = S.apply_work(0), per_iteration = S.apply_work(1) - per_apply;
  EXPECT_GT(per_iteration, 1.0);
  EXPECT_NEAR(per_apply, 2.0 / double(P.grid.nz()), 1e-12);
  EXPECT_GT(R.operator_applications, R.outer_iterations);
  EXPECT_NEAR(R.fine_matvecs, double(R.inner_iterations) * per_iteration + double(R.operator_applications) * per_apply,
              1e-9 * R.fine_matvecs);
}
}  // namespace tresca
namespace tresca {
// |S x| <= contact_stiffness_bound |x| (the Newton step's accuracies rest on
// it) against the dense Schur complement's largest eigenvalue: a bound on
// every mesh shape, not a loose one (4 times the largest diagonal entry, the
// estimate before, was 4 % under it on meshes one element thick)
TEST(SteklovPoincare, StiffnessBoundHoldsOnEveryMeshShape) {
  for (const auto& d : {std::array<index, 3>{40, 1, 1}, std::array<index, 3>{12, 6, 6}, std::array<index, 3>{4, 8, 8},
                        std::array<index, 3>{24, 12, 1}}) {
    const Problem P = make_problem(spec_for_dims(d[0], d[1], d[2]));
    const DenseSchur D = dense_schur(P);
    const real lmax = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(D.S, Eigen::EigenvaluesOnly).eigenvalues().maxCoeff();
    const real bound = contact_stiffness_bound(P);
    EXPECT_GE(bound, lmax) << d[0] << "x" << d[1] << "x" << d[2];
    EXPECT_LE(bound, 5 * lmax) << d[0] << "x" << d[1] << "x" << d[2];  // (2.6-4.2 on the shapes measured)
  }
}
}  // namespace tresca
