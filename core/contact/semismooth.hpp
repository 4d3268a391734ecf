// Semismooth* Newton method for the condensed Tresca contact problem
// (paper Section 4, method.md §3–5), matrix-free on the contact boundary.
//
// Iteration k, x = (u, lambda), r = S u − b̃ (the contact forces that hold
// the body at u) and the body's displacement U = E u + K_ii^{-1} l_i:
//  1. approximation step (kernels/contact_maps.hpp) at scale s → d̂, node
//     status; the residual in consistent units |w| [N] for the stopping rule
//     |w| <= eps (the paper's |v̂| <= eps (11) with StopRule::paper) and as
//     the line search's merit;
//  2. Newton step (9)–(10) in reduced form, with v = d̂ − x the step's
//     increments: known Δu_τ = v_12 (sticking), Δu_z = v_4/s (contact),
//     Δλ = v_4 (separated); free dofs F = u_τ of sliding nodes, u_z of
//     separated nodes solve the SPD system
//       (S + H)_FF Δu_F = r_F − S_F,known Δu_known
//     with r = (s I + H_1) v_12 on sliding rows, v_3 + v_4 on separated rows,
//     by CG preconditioned with BoundaryPreconditioner; then
//     Δλ = (S Δu)_z − v_3 on contact nodes.
//  3. S Δu and E Δu from one application of S to the whole step, warm from
//     the outer CG's running E Δu; then the step's length alpha by the
//     line search on the envelope, or on |w| near the solution
//     (NewtonOptions::line_search, envelope_merit; r, lambda
//     and U are linear along the step, so trial points cost no solve):
//     x += alpha Δ, r += alpha S Δu, U += alpha E Δu.
// Tolerances. The step is inexact: CG stops at eta_k |r_F| (forcing term,
// Eisenstat–Walker choice 2: eta_0 = forcing_max, then 0.9 (|v̂_k|/|v̂_k-1|)²,
// safeguarded, so eta_k -> 0 and the convergence stays superlinear), floored
// at 0.1 eps. Its inner (K_ii) solves are relaxed as the outer residual r_j
// falls: inner rtol_j = clamp(target / ||r_j||, 1e-12, 1e-2) (a safety factor 0.1 cost
// 6-13% more work and saved no Newton step, perf/RESULTS.md §0c); each
// step's system is checked with its fresh S Δu, and two steps in a row
// that missed their accuracy, leaving more than a tenth of r_F (S a small
// difference of large terms: ν near −1), divide every later inner
// tolerance by the factor missed (NewtonResult::inner_tightening, §0ze). The
// residual r needs the accuracy of its use: residual_fraction eta_k |v̂_k|
// absolute for the step it decides (an error of that size is a part of the
// step's own inexactness), and residual_accuracy |b̃| before |v̂| <= eps is
// believed. The first r is loose (one solve, SteklovPoincare::residual: a
// nested or restarted x0 is far from the solution in |v̂|); each S Δu is
// solved to the accuracy of its step; where r is too loose for its use it
// is refreshed by a solve warm from U, which only corrects. Increments keep
// r near convergence: a fresh r has the rounding error of r itself (~1e-13
// |b̃|), an increment that of the increment.
// The paper's unscaled step compares forces with displacements (1 N against
// nodal forces of 1e7 N), so an error of 1e-8 in a force moves its decisions:
// it needs eta = 1e-10 (NewtonOptions::paper_method()). The scaled step
// compares both in consistent units and takes eta_0 = 1e-2.
// Cost per step: outer iterations + 2 S applications (known increments,
// S Δu) = inner MG-CG solves, and now and then a refresh of r.
#pragma once
#include <algorithm>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/contact/friction.hpp"
#include "core/contact/steklov.hpp"
#include "kernels/contact_maps.hpp"

namespace tresca {

// outer_failure: two Newton steps in a row whose boundary CG stopped at its
// iteration limit, the second also when solved again 3 times with tighter
// inner solves (the step systems are not being solved: e.g. nearly
// incompressible material, where it used to grind on for minutes), or a
// boundary Krylov solve that broke down (a direction of zero or negative
// curvature: the step's operator or its preconditioner not positive);
// inner_failure: a K_ii solve of an application of S failed
enum class NewtonReason { converged, iteration_limit, stagnation, inner_failure, non_finite, outer_failure };
const char* to_string(NewtonReason r);

struct NewtonProgress {
  int iteration;
  real residual;  // the stopping quantity of this approximation step (NewtonOptions::stop)
  index active, separated, sticking, sliding;
  long long inner_iterations, outer_iterations;  // cumulative
  double elapsed;
  // the iterate itself, valid during the call: u (3p), lambda (p), the
  // contact forces r = S u - b̃ (3p), status and bound of this step (p)
  const std::vector<real>* u = nullptr;
  const std::vector<real>* lambda = nullptr;
  const std::vector<real>* r = nullptr;
  const std::vector<std::uint8_t>* status = nullptr;
  const std::vector<real>* phi = nullptr;
  real step_length = 1;  // alpha of the step that led here (1: full; the first iterate: 1)
};

enum class OuterPreconditioner { multigrid, none };

// Metric of the approximation step (contact_maps.hpp): the paper's (s = 1:
// forces and displacements added as numbers) or a stiffness per contact node
// from the diagonal of K_cc (consistent units; issue 9, item 4).
enum class StepScaling { paper, diagonal };

// The stopping quantity: the residual in consistent units |w| [N]
// (contact_maps.hpp: displacement parts times the node's stiffness s_i),
// or the paper's |v̂| of its rule (11), which adds metres to newtons (with
// E = 7e10 and phi = 5e6 it stopped at 4e-7 while a slip direction was
// 1e4 N off); the paper's for --table only.
enum class StopRule { consistent, paper };

// Where the energy's envelope is a merit (NewtonOptions::envelope_merit):
// the scaled step, with a bound that does not follow lambda (an energy is
// minimised: Tresca, and Coulomb's fixed-point loop of Tresca solves)
inline bool envelope_applies(StepScaling scaling, const FrictionLaw& friction) {
  return scaling == StepScaling::diagonal && !friction.bound_follows_lambda();
}

// The scale of Newton's accuracies from the norm |b̃| [N] of the condensed
// load: |b̃| itself, or 1 N where there is no load at all (b̃ = 0, whose
// solution u = 0 any scale accepts).
inline real force_scale_of(real btilde_norm) { return btilde_norm > 0 ? btilde_norm : real(1); }

struct NewtonOptions {
  real eps = 1e-6;  // [N]
  real rtol = 0;    // stop at |w| <= max(eps, rtol |w_0|) (0: absolute)
  StopRule stop = StopRule::consistent;
  // preconditioner of the reduced boundary system: one V-cycle of K + B
  // (boundary_preconditioner.hpp), or none (plain CG, for comparison)
  OuterPreconditioner outer_pc = OuterPreconditioner::multigrid;
  int max_iterations = 50;
  StepScaling scaling = StepScaling::diagonal;
  real forcing_max = 1e-2;     // largest relative accuracy of a Newton step (the first)
  // accuracy of r = S u - b̃ (relative to |b̃|, absolute): at convergence,
  // and as a fraction of eta_k |v̂_k| before (Tolerances); the first r,
  // relative to its right-hand side
  real residual_accuracy = 1e-12;
  real residual_fraction = 0.1;
  real initial_residual_rtol = 1e-4;
  // Globalisation: a non-monotone backtracking line search on the merit |w|
  // (Grippo–Lampariello–Lucidi): a step of length alpha in 1, 1/2, ... is
  // taken once |w(x + alpha Δ)| <= (1 - 1e-4 alpha) max of the last
  // line_search_memory + 1 merits, so a step may rise above the last value
  // (semismooth Newton wanders while the active set settles) but the
  // window's maximum falls. Trial points cost no solve: r, lambda and the
  // body are linear along the step, whose S Δu the update computes anyway.
  // Where no length down to 2^-line_search_halvings decreases the merit, a
  // step whose boundary system was solved to its tolerance is taken whole
  // all the same, once in line_search_memory + 1 steps (a watchdog): a
  // change of the active set can raise |w| for one step that the next
  // brings down, e.g. a cold start over a gap, whose first step falls
  // freely through the obstacle (|w| of the penetration: s times metres)
  // and whose second puts the nodes on it (NewtonResult::watchdog_steps).
  // Stagnation, evidence that Newton is not converging: no length decreases
  // the merit and the watchdog may not step, or the best merit of the last
  // stagnation_window steps is not below half the best before them (the
  // round-off floor of an unattainable eps, where the non-monotone search
  // would let the iterates wander) while the last step did not both change
  // some node's state and lower the merit (a front of separation that
  // advances a node or two a step is slow progress, not stagnation; the
  // iteration limit bounds it). The first time the window test holds, the
  // search turns monotone instead (memory 0: each step must lower the
  // merit; NewtonResult::monotone_from), and from there, where the merit
  // far from the solution is an energy's envelope (envelope_merit), the
  // window test no longer ends the run: Newton cannot cycle, a descent to
  // the energy's minimiser is progress however slow, and the iteration
  // limit bounds it (where no energy is minimised, Coulomb's Newton, a
  // second holding ends it: stagnation; a 9x5x6 block of elements 68:1 crept
  // for 19 steps after the switch and converged at step 39, RESULTS.md
  // §0zu). A semismooth Newton that cycles between two active sets, each
  // step's |w| inside the window's maximum, is pulled out of the cycle: a
  // 6x17x6 block on a cylinder cycled between 17 and 18 nodes in contact
  // and now converges (§0zq). Runs that converge without it never reach
  // the test and are unchanged.
  // Off: full steps, and only the second test.
  bool line_search = true;
  // Far from the solution the search's merit is the problem's own: the
  // forward-backward envelope of the Tresca energy in the step's metric s
  // (contact_maps.hpp: envelope_change), a continuous function of u whose
  // minimiser is the solution and along which Newton's direction descends
  // (it is the envelope's Newton direction where s bounds S). |w| is not
  // such a merit: a full step that crossed many nodes' kinks could raise
  // the energy while |w| fell, and Newton cycled or crept (a 25x4x7 plate
  // pressed and sheared over a gap: 50 steps, 2e6 N left; with the
  // envelope 7 steps; RESULTS.md §0zs). A full step that halves the least
  // |w| so far is taken (Newton converging; the envelope in the metric s,
  // which need not bound S, can rise along it; halving the last |w| alone
  // let a full step and a short one alternate to the iteration limit,
  // §0zx); else a length where the envelope falls;
  // where its change is below what its terms resolve
  // (near the solution, and a step that moves only lambda) |w| decides as
  // above. Only where an energy is minimised: the scaled step with a bound
  // that does not follow lambda (Tresca, Coulomb's fixed-point loop).
  bool envelope_merit = true;
  // A stagnation at the floor of what r resolves, the level |w| stayed at
  // with the contact states settled (semismooth.cpp: floor_stop), counts
  // as converged where that level is at most floor_rtol |b̃| (run_tresca
  // caps it at RunOptions::kkt_rtol, the final check's tolerance); 0: never.
  real floor_rtol = 1e-10;
  bool kink_contact = true;  // contact_maps.hpp: ContactLaw::kink_contact
  int line_search_memory = 5;
  int line_search_halvings = 10;
  int stagnation_window = 10;
  std::function<void(const NewtonProgress&)> progress;
  // The paper's method: unscaled approximation step, whose decisions compare
  // forces with displacements, so its steps must be near-exact.
  static NewtonOptions paper_method() {
    NewtonOptions o;
    o.scaling = StepScaling::paper;
    o.stop = StopRule::paper;
    o.forcing_max = 1e-10;
    o.line_search = false;
    o.kink_contact = false;
    return o;
  }
  // optional initial iterate (default x0 = 0): u0 (3p) and lambda0 (p), host values
  const std::vector<real>* u0 = nullptr;
  const std::vector<real>* lambda0 = nullptr;
  // optional: a guess of the body's displacement at u0 (S.full_size(),
  // steklov.hpp: residual), e.g. a coarser mesh's, interpolated. Taken: the
  // solve moves it into its result's body (left empty), so that one copy of
  // the body lives, not two
  Field<real>* body0 = nullptr;
  // |b̃| [N], the scale of r's absolute accuracy; 0: |r| at x0 = 0 (= |b̃|).
  // Required with u0 (e.g. from a loose SteklovPoincare::condensed_load,
  // through force_scale_of).
  real force_scale = 0;
  // optional, with body0 and force_scale: r0 = S u0 - b̃ of that body to
  // residual_accuracy, e.g. an earlier solve's NewtonResult::r and ::body
  const std::vector<real>* r0 = nullptr;
  real r0_accuracy = 0;  // r0's accuracy relative to force_scale (0: residual_accuracy)
  // the divisor (>= 1) of every inner tolerance to start from, which the
  // solve raises where steps miss their accuracy (NewtonResult::inner_tightening):
  // nested iteration and the Coulomb fixed point pass on an earlier solve's
  real inner_tightening = 1;
  // Tresca: the law's bounds phi. Coulomb lagged: phi_i = F lambda_i of the
  // current iterate before every approximation step (the law's phi is then
  // ignored); ||v̂|| with that bound is the Coulomb problem's own residual,
  // so the stopping rule stays; the step does not differentiate phi (a
  // quasi-Newton step, still symmetric). Coulomb newton: the step also
  // differentiates phi (not symmetric: boundary GMRES with the same
  // preconditioner, semismooth.cpp). A fixed point runs whole Tresca solves
  // (coulomb.hpp) and is refused here.
  FrictionLaw friction;
};

// Host values (the iteration's own vectors live where the launches run and
// are copied out at its end), except body, a Field where the launches ran.
struct NewtonResult {
  NewtonReason reason = NewtonReason::iteration_limit;
  int iterations = 0;                  // Newton steps taken
  std::vector<real> history;           // the stopping quantity after each approximation step (first at x0)
  std::vector<real> merit;             // |w| [N] there (the line search's merit; = history for StopRule::consistent)
  std::vector<real> step_lengths;      // alpha of each step taken (1: a full Newton step)
  real tolerance = 0;                  // the stopping test's max(eps, rtol |·_0|), or what r resolves
                                       // (residual_accuracy |b̃|) where a fresh r confirmed a stop to that
  std::vector<long long> inner_history, outer_history;  // cumulative inner / outer CG iterations there
  std::vector<real> u, lambda, r;      // 3p, p, 3p: r = S u - b̃ (to residual_accuracy if converged)
  Field<real> body;                    // U = E u + K_ii^{-1} l_i (S.full_size()) of that r
  real force_scale = 0;                // |b̃| used for the accuracies
  std::vector<std::uint8_t> status;    // per node: kContact | kStick at the last approximation step
  std::vector<real> phi;               // the Tresca bound of the last approximation step
  std::vector<real> scale;             // the steps' metric s_i (step_scale), empty: the paper's (s = 1)
  std::vector<real> units;             // the stiffness s_i of the consistent units (step_scale) [N/m]
  StopRule stop = StopRule::consistent;
  bool kink_contact = true;            // the options' kink rule (the status above)
  long long outer_iterations = 0, inner_iterations = 0, operator_applications = 0;
  int outer_limit_hits = 0;      // Newton steps whose outer CG stopped at its iteration limit
  int watchdog_steps = 0;        // steps taken whole where no length decreased |w| (NewtonOptions::line_search)
  int envelope_steps = 0;        // steps whose length the energy's envelope chose (NewtonOptions::envelope_merit)
  int redone_steps = 0;          // steps solved again with tighter inner solves (NewtonSolve::take_step: unfit)
  int monotone_from = -1;        // the iteration from which the line search was monotone (-1: never; line_search)
  // > 0: converged at this floor of what r resolves [N], above eps: the
  // level |w| stayed at (NewtonOptions::floor_rtol); tolerance is then it
  real residual_floor = 0;
  // > 0: what r resolved at the iterate as measured (two fresh r, warm and
  // cold, differed by this [N]) where the floor was above floor_rtol |b̃|
  real floor_measured = 0;
  index last_state_changes = 0;  // nodes whose contact or stick state the last step changed (all ranks)
  // the factor (>= 1) by which the steps' inner tolerances were tightened
  // where two steps in a row, checked with a fresh S Δu, missed their accuracy
  real inner_tightening = 1;
  // work in fine-grid matvec equivalents, from the solvers' own counts and
  // cost models (SteklovPoincare::apply_work, BoundaryPreconditioner::apply_work)
  double fine_matvecs = 0;
  bool converged() const { return reason == NewtonReason::converged; }
};

// The contact law per contact node: Tresca bound phi_i >= 0 [N] and initial
// gap g_i >= 0 [m] to the rigid obstacle (non-penetration u_z + g_i >= 0).
struct ContactConditions {
  std::vector<real> phi, gap;
  static ContactConditions uniform(index p, real phi, real gap) { return {std::vector<real>(p, phi), std::vector<real>(p, gap)}; }
  ContactLaw law(bool kink_contact = true) const { return {phi.data(), gap.data(), kink_contact}; }
  // Coulomb's bound at lambda (p host values): phi_i = F max(0, lambda_i)
  void set_coulomb_bound(real F, const std::vector<real>& lambda);
};

// s_i = (K_xx + K_yy + K_zz)/3 at contact node i [N/m]: the diagonal of S
// is smaller, but the iteration counts do not depend on a factor in 0.25..2
// (perf/RESULTS.md), so the plain diagonal of K_cc it is
std::vector<real> step_scale(const SteklovPoincare& S);

// A bound on the largest eigenvalue of S [N/m], |S x| <= bound |x|: S <= K_cc
// (a Schur complement of K), whose largest eigenvalue is at most its largest
// absolute row sum (Gershgorin); a contact node lies in at most 4 bricks,
// so a row of K_cc sums at most 4 rows of the brick matrix. (4 times the
// largest diagonal entry, the estimate before, was 4 % under the largest
// eigenvalue on meshes one element thick.)
real contact_stiffness_bound(const Problem& P);

// The window test above on the merit history h (window w), on the entries
// from `from` on (those since the line search turned monotone)
bool stagnated(const std::vector<real>& h, int w, int from = 0);

NewtonResult semismooth_newton(const SteklovPoincare& S, const ContactConditions& law, const NewtonOptions& opt);

}  // namespace tresca
