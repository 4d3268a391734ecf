#include "core/contact/run.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/contact/nested.hpp"
#include "core/parallel/comm.hpp"
#include "core/multigrid/multigrid.hpp"
#include "core/parallel/row_fetch.hpp"
#include "kernels/contact_maps.hpp"
#include "kernels/launch.hpp"
#include "kernels/transfer.hpp"
#include "kernels/vector_ops.hpp"
#include "core/util/profile.hpp"

namespace tresca {

ContactConditions contact_conditions(const ProblemSpec& spec) {
  const GridDims g = grid_of(spec);
  const index p = spec.contact_nodes();
  ContactConditions c = ContactConditions::uniform(p, spec.phi, 0);
  for (index i = 0; i < p; ++i) {
    const auto [x, y] = contact_position(g, i);
    c.gap[i] = spec.obstacle.gap_at(x, y);
  }
  return c;
}

namespace {

// What this mesh's Newton starts from: the coarser mesh's solution
// (interpolated), a given initial iterate, and the guesses of the body and
// of K_ii^{-1} l_i; NewtonOptions points into it
struct Start {
  std::vector<real> u0, lambda0;  // the coarser mesh's (empty: none)
  Field<real> load_guess;         // K_ii^{-1} l_i, interpolated
  Field<real> body;               // the guess at u0, then U = E u + K_ii^{-1} l_i
  const std::vector<real>* given_u0 = nullptr;  // a restart's or continuation's
  const std::vector<real>* given_lambda0 = nullptr;
  std::vector<real> local[4];  // this rank's part of u0, lambda0, given u0, given lambda0
  Field<real> given_body;
  std::vector<real> r0, r_given;
};

// Nested iteration: the coarser mesh first (before this mesh's operators
// exist, so the peak memory stays this mesh's). It hands up (u, lambda) as
// the Newton initial iterate and, trilinearly interpolated, its body and
// K_ii^{-1} l_i as initial guesses of this mesh's first residual and |b̃|.
void solve_coarser_mesh(const ProblemSpec& spec, const RunOptions& opt, RunResult& R, Start& start,
                        NewtonOptions& newton) {
  const ProblemSpec cs = coarser_spec(spec);
  RunOptions co = opt;
  co.newton.u0 = co.newton.lambda0 = nullptr;  // (a given iterate is this mesh's)
  co.recover_interior = true;
  co.keep_interior_load = true;
  co.newton.progress = nullptr;
  co.iterate_done = nullptr;
  co.phase_done = nullptr;  // one line per coarse mesh: nested_done
  co.newton.rtol = opt.nested_rtol;
  co.newton.max_iterations = opt.newton.max_iterations * std::max(1, opt.nested_iteration_factor);
  co.nested_iteration_factor = 1;
  co.cold_restart = false;
  co.coulomb_tol = std::max(opt.coulomb_tol, opt.nested_rtol);
  // and need their forces only to a fraction of that accuracy
  co.tight_rtol = std::max(opt.tight_rtol, 1e-3 * opt.nested_rtol);
  co.newton.residual_accuracy = std::max(opt.newton.residual_accuracy, 1e-3 * opt.nested_rtol);
  co.contact = coarse_conditions(R.problem->grid, R.contact, grid_of(cs));
  // in a device run, a mesh under device_min_nodes() is solved on the host,
  // as the multigrid's small levels are: a whole solve's thousands of
  // launches would cost more than its work (perf/RESULTS.md §0y)
  const bool on_device = launch_on_device() && cs.nodes() >= device_min_nodes();
  RunResult C;
  {
    const HostLaunches where(!on_device);
    C = run_tresca(cs, co);
  }
  R.nested = C.nested;
  R.nested.push_back({cs, int(C.newton_steps()), C.converged(), C.fine_matvecs_total - C.nested_fine_matvecs,
                      C.times.total - C.times.nested, on_device});
  R.nested_fine_matvecs = C.fine_matvecs_total * double(cs.free_dofs()) / double(spec.free_dofs());
  if (opt.nested_done) opt.nested_done(R.nested.back());
  // (a material whose S products need tighter inner solves needs them on every mesh)
  newton.inner_tightening = std::max(newton.inner_tightening, C.newton.inner_tightening);
  if (!C.converged()) return;
  prolongate_contact(C.problem->grid, C.newton.u, C.newton.lambda, R.problem->grid, start.u0, start.lambda0);
  newton.u0 = &start.u0;
  newton.lambda0 = &start.lambda0;
  // on the slab this mesh's operators will use (the whole grid on one rank)
  const Comm& comm = Comm::world();
  const Comm& split = split_over(R.problem->grid, comm);  // as SteklovPoincare's
  const Slab fine = make_slab(R.problem->grid, split.rank(), split.size());
  const index n = 3 * fine.local.nodes();
  start.load_guess.resize(n);
  start.body.resize(n);
  // (the coarser run's results are host values: back where the launches run)
  C.interior_load.move_to(launch_space());
  C.u_full.move_to(launch_space());
  prolongate_slabs(C.slab, C.interior_load.data(), fine, start.load_guess.data(), comm);
  prolongate_slabs(C.slab, C.u_full.data(), fine, start.body.data(), comm);
  newton.body0 = &start.body;
}

// RunOptions::iterate_done: each iterate's body (E u from one S apply, plus
// K_ii^{-1} l_i) and every contact node's values (several ranks: gathered)
void show_iterates(const SteklovPoincare& S, const RunOptions& opt, RunResult& R, NewtonOptions& newton) {
  const Slab rows = S.slab();
  newton.progress = [S = &S, R = &R, done = opt.iterate_done, rows, shown = newton.progress,
                     step = 0](const NewtonProgress& pr) mutable {
    if (shown) shown(pr);
    const Field<real> u_placed = placed_field<real>(*pr.u);
    Field<real> r(pr.u->size()), u_full(S->full_size());
    S->residual(u_placed.data(), r.data(), 1e-8, u_full.data());
    S->exchange_ghosts(u_full.data());
    u_full.move_to(Space::host);  // (an output)
    const std::vector<real> u = S->whole(*pr.u, 3), lambda = S->whole(*pr.lambda, 1), rw = S->whole(*pr.r, 3),
                            phi = S->whole(*pr.phi, 1);
    const std::vector<std::uint8_t> status = S->whole(*pr.status);
    NewtonProgress whole = pr;
    whole.u = &u;
    whole.lambda = &lambda;
    whole.r = &rw;
    whole.phi = &phi;
    whole.status = &status;
    done(Iterate{R->problem.get(), step++, &whole, &u_full, &R->contact.gap, &rows});
  };
}

// this rank's contact nodes (all of them on one rank): the law and the initial iterates
ContactConditions this_ranks_part(const SteklovPoincare& S, const ContactConditions& all, NewtonOptions& newton,
                                  Start& start) {
  ContactConditions law = all;
  if (!S.distributed()) return law;
  law.phi = S.local_part(all.phi, 1);
  law.gap = S.local_part(all.gap, 1);
  auto localise = [&](const std::vector<real>*& u, const std::vector<real>*& lambda, std::vector<real>* part) {
    if (!u || !lambda) return;
    part[0] = S.local_part(*u, 3);
    part[1] = S.local_part(*lambda, 1);
    u = &part[0];
    lambda = &part[1];
  };
  localise(newton.u0, newton.lambda0, start.local);
  localise(start.given_u0, start.given_lambda0, start.local + 2);
  return law;
}

// A given initial iterate (a restart, a continuation) competes with the
// coarser mesh's solution: Newton starts from the one of smaller merit |w|
// (a continuation step in phi or load can leave the old solution further
// from the new one than the cheap coarse solve is). Both are measured at the
// first residual's accuracy, each body warm for Newton.
void choose_initial_iterate(const SteklovPoincare& S, const RunOptions& opt, const ContactConditions& law,
                            NewtonOptions& newton, Start& start, RunResult& R) {
  if (!start.given_u0) return;
  if (!newton.u0) {
    newton.u0 = start.given_u0;
    newton.lambda0 = start.given_lambda0;
    return;
  }
  const std::vector<real> units = step_scale(S);
  // (to 1e-2: the merits differ by factors; the winner's r, body and that
  // accuracy go to Newton, which refines r where it needs to)
  const real choice_rtol = 1e-2;
  auto merit = [&](const std::vector<real>& u, const std::vector<real>& lambda, Field<real>& b,
                   std::vector<real>& r, bool warm) {
    const index p = S.contact_nodes();
    b.resize(S.full_size());
    {  // the solve where the launches run, the merit of its result on the host
      const Field<real> u_placed = placed_field<real>(u);
      Field<real> r_placed(3 * p);
      const SolveStats st_r =
          S.residual(u_placed.data(), r_placed.data(), choice_rtol, b.data(), warm ? b.data() : nullptr);
      R.choice_fine_matvecs += S.apply_work(st_r.iterations);
      r = r_placed.to_vector();
    }
    HostLaunches host;
    std::vector<real> v(4 * p), w(4 * p), d(3 * p);
    std::vector<std::uint8_t> st(p);
    ContactConditions l = law;
    if (opt.friction.is_coulomb()) l.set_coulomb_bound(opt.friction.F, lambda);
    const ResidualNorms n = approximation_step(p, l.law(newton.kink_contact), nullptr, units.data(), u.data(),
                                               lambda.data(), r.data(), v.data(), w.data(), d.data(), st.data());
    return std::sqrt(S.sum(n.consistent));
  };
  const real coarse = merit(*newton.u0, *newton.lambda0, start.body, start.r0, true);
  const real given = merit(*start.given_u0, *start.given_lambda0, start.given_body, start.r_given, false);
  R.initial_iterate = given <= coarse ? "given" : "coarser mesh";
  if (opt.phase_done) {
    const std::string what = "initial iterate: the " + R.initial_iterate + "'s (|w| given " + std::to_string(given) +
                             " N, coarser mesh " + std::to_string(coarse) + " N)";
    opt.phase_done(what.c_str(), 0);
  }
  if (given <= coarse) {
    newton.u0 = start.given_u0;
    newton.lambda0 = start.given_lambda0;
    start.body = std::move(start.given_body);
    start.r0 = std::move(start.r_given);
  }
  start.given_body = {};  // (the loser's body: not held through Newton)
  newton.r0 = &start.r0;
  newton.r0_accuracy = choice_rtol;
}

// |b̃|, the scale of Newton's absolute accuracies and of the report: from
// x0 = 0 Newton's first residual is -b̃ (nothing to do here); an initial
// iterate takes a loose solve of its own (a coarser mesh of nested
// iteration always, to hand up its K_ii^{-1} l_i). The finest mesh of nested
// iteration takes it from the coarser mesh's K_ii^{-1} l_i, without a solve:
// a scale to about 1 %, for three inner iterations fewer (perf/RESULTS.md §0zp).
SolveStats scale_of_load(const SteklovPoincare& S, const RunOptions& opt, NewtonOptions& newton, Start& start,
                         RunResult& R) {
  SolveStats cond;
  if (newton.u0 || opt.keep_interior_load) {
    Field<real> btilde;
    if (!opt.keep_interior_load && !start.load_guess.empty()) {
      S.condensed_load_from(start.load_guess.data(), btilde);
      R.btilde_estimated = true;
    } else {
      cond = S.condensed_load(opt.scale_rtol, btilde, opt.keep_interior_load ? &R.interior_load : nullptr,
                              start.load_guess.empty() ? nullptr : start.load_guess.data());
    }
    newton.force_scale = force_scale_of(std::sqrt(S.sum(dot(index(btilde.size()), btilde.data(), btilde.data()))));
  }
  start.load_guess = {};
  return cond;
}

// Coulomb: max_i |phi_i - F lambda_i| of the run's solution, over the ranks
void coulomb_consistency(const SteklovPoincare& S, const RunOptions& opt, const ContactConditions& law, RunResult& R) {
  if (!R.coulomb()) return;
  R.coulomb_consistency = 0;
  for (index i = 0; i < S.contact_nodes(); ++i)
    R.coulomb_consistency = std::max(R.coulomb_consistency,
                                     std::abs(law.phi[i] - opt.friction.F * std::max(real(0), R.newton.lambda[i])));
  R.coulomb_consistency = S.max(R.coulomb_consistency);
}

// Coulomb by one Newton solve whose bound followed lambda: that solve is the
// loop's account, and its last bound the law's
void one_solve_as_coulomb_loop(ContactConditions& law, RunResult& R) {
  law.phi = R.newton.phi;
  R.coulomb_loop.iterations = 1;
  R.coulomb_loop.reason = R.newton.converged() ? CoulombReason::converged : CoulombReason::tresca_failed;
  R.coulomb_loop.newton_steps = R.newton.iterations;
  R.coulomb_loop.inner_iterations = R.newton.inner_iterations;
  R.coulomb_loop.fine_matvecs = R.newton.fine_matvecs;
}

// The contact problem by the friction law's method: one semismooth* Newton
// solve (Tresca; Coulomb by Newton with the bound following lambda), or
// Coulomb's fixed point of Tresca solves. `law` ends with the bound used.
void solve_contact(const SteklovPoincare& S, const RunOptions& opt, ContactConditions& law, NewtonOptions& newton,
                   RunResult& R) {
  if (opt.friction.bound_follows_lambda()) {
    newton.friction = opt.friction;
    R.newton = semismooth_newton(S, law, newton);
    one_solve_as_coulomb_loop(law, R);
  } else if (opt.friction.is_coulomb()) {
    CoulombOptions co;
    co.F = opt.friction.F;
    co.tol = opt.coulomb_tol;
    R.coulomb_loop = coulomb_fixed_point(S, law, co, newton);
    R.newton = std::move(R.coulomb_loop.last);
    R.coulomb_loop.last = {};
    law = R.coulomb_loop.law;
  } else {
    R.newton = semismooth_newton(S, law, newton);
  }
  coulomb_consistency(S, opt, law, R);
}

// b's steps after a's, b having started from a's last iterate: one account
void append_steps(NewtonResult& a, NewtonResult&& b) {
  const int k0 = a.iterations;
  const long long in0 = a.inner_iterations, out0 = a.outer_iterations;
  a.reason = b.reason;
  a.iterations += b.iterations;
  // (b's first entries are a's last iterate, measured again with a fresh r)
  a.history.insert(a.history.end(), b.history.begin() + 1, b.history.end());
  a.merit.insert(a.merit.end(), b.merit.begin() + 1, b.merit.end());
  a.step_lengths.insert(a.step_lengths.end(), b.step_lengths.begin(), b.step_lengths.end());
  for (size_t j = 1; j < b.inner_history.size(); ++j) {
    a.inner_history.push_back(in0 + b.inner_history[j]);
    a.outer_history.push_back(out0 + b.outer_history[j]);
  }
  a.u = std::move(b.u);
  a.lambda = std::move(b.lambda);
  a.r = std::move(b.r);
  a.body = std::move(b.body);
  a.status = std::move(b.status);
  a.phi = std::move(b.phi);
  a.outer_iterations += b.outer_iterations;
  a.inner_iterations += b.inner_iterations;
  a.operator_applications += b.operator_applications;
  a.outer_limit_hits += b.outer_limit_hits;
  a.watchdog_steps += b.watchdog_steps;
  a.envelope_steps += b.envelope_steps;
  a.redone_steps += b.redone_steps;
  if (b.monotone_from >= 0) a.monotone_from = k0 + b.monotone_from;
  a.residual_floor = b.residual_floor;
  a.floor_measured = b.floor_measured;
  a.tolerance = std::max(a.tolerance, b.residual_floor);
  a.last_state_changes = b.last_state_changes;
  a.inner_tightening = b.inner_tightening;
  a.fine_matvecs += b.fine_matvecs;
}

// A stop at |w| <= eps that the final check does not confirm: its KKT
// fields weigh w's error differently (a slowly sliding node's direction
// |r_τ + φ u_τ/|u_τ|| by about φ / (s |u_τ|)), or the fresh r puts |w|
// itself above the tolerance (the r summed from the steps had drifted).
// Newton goes on once from its own result, with the check's fresh r and
// body, to eps lowered by twice the factor the check missed; the check then
// runs again against the tolerance the user asked for
// (RunResult::resumed_from); `elapsed`: the seconds since the first solve
// began (its progress lines go on). s11_005 and s11_093 of the random sweep
// stopped at |w| 2.6e-7 and 4.8e-7 N with a direction 1.4e-6 and 2.0e-6 N
// over eps = 1e-6 (RESULTS.md §0zr); s7_023 with coarse meshes down to 8
// contact nodes at a summed |w| of 9.6e-7 N that the fresh r put at 1.005e-6
// (RESULTS.md §0zw).
// False where it does not apply (a Coulomb fixed point, the paper's rule,
// a stop at the floor of what r resolves, or a check that passed).
bool resume_after_check(const SteklovPoincare& S, const RunOptions& opt, ContactConditions& law,
                        NewtonOptions& newton, Field<real>& body, double elapsed, RunResult& R) {
  const NewtonResult& N = R.newton;
  const FinalReport& F = R.report;
  const real missed = std::max(F.kkt_force, F.true_residual_consistent) / F.tolerance;
  if (!N.converged() || F.kkt_ok || N.residual_floor > 0 || N.stop != StopRule::consistent ||
      (opt.friction.is_coulomb() && !opt.friction.bound_follows_lambda()) || !(missed > 1) ||
      !std::isfinite(missed) || N.history.empty())
    return false;
  NewtonOptions again = newton;
  again.eps = 0.5 * N.history.back() / missed;
  again.rtol = 0;
  again.u0 = &N.u;
  again.lambda0 = &N.lambda;
  again.body0 = &body;
  again.r0 = &F.r;
  again.r0_accuracy = opt.tight_rtol;
  again.force_scale = N.force_scale;
  again.inner_tightening = N.inner_tightening;
  const int k0 = N.iterations;
  if (newton.progress)  // (numbered on from the first solve's, its last iterate not again)
    again.progress = [&newton, k0, in0 = N.inner_iterations, out0 = N.outer_iterations,
                      t0 = elapsed](const NewtonProgress& pr) {
      if (pr.iteration == 0) return;
      NewtonProgress shifted = pr;
      shifted.iteration += k0;
      shifted.inner_iterations += in0;
      shifted.outer_iterations += out0;
      shifted.elapsed += t0;
      newton.progress(shifted);
    };
  // (newton.friction is the run's: solve_contact)
  NewtonResult more = semismooth_newton(S, law, again);
  R.resumed_from = k0;
  R.resumed_eps = again.eps;
  append_steps(R.newton, std::move(more));
  if (opt.friction.bound_follows_lambda()) one_solve_as_coulomb_loop(law, R);
  return true;
}

// the run's results for every contact node on every rank (outputs, the next
// finer mesh of nested iteration)
void gather_contact_values(const SteklovPoincare& S, ContactConditions& law, RunResult& R) {
  if (!S.distributed()) return;
  NewtonResult& N = R.newton;
  N.u = S.whole(N.u, 3);
  N.lambda = S.whole(N.lambda, 1);
  N.r = S.whole(N.r, 3);
  N.status = S.whole(N.status);
  N.phi = S.whole(N.phi, 1);
  if (!N.scale.empty()) N.scale = S.whole(N.scale, 1);
  law.phi = S.whole(law.phi, 1);
  law.gap = S.whole(law.gap, 1);
  R.report.r = S.whole(R.report.r, 3);
  R.report.status = S.whole(R.report.status);
}

}  // namespace

std::string run_rank_layout(const ProblemSpec& spec) {
  return rank_layout(grid_of(spec), Comm::world(), "each rank solves the whole mesh");
}

double run_memory_per_rank(const ProblemSpec& spec) {
  return estimated_memory_bytes_per_rank(spec, split_over(grid_of(spec), Comm::world()).size());
}

RunResult run_tresca(const ProblemSpec& spec, const RunOptions& opt) {
  RunResult R;
  R.friction = opt.friction;
  const double t0 = wall_time();
  R.problem = std::make_unique<Problem>(make_problem(spec));
  R.contact = opt.contact.phi.empty() ? contact_conditions(spec) : opt.contact;
  NewtonOptions newton = opt.newton;
  // (a stop at a measured floor must stay within the final check's tolerance)
  newton.floor_rtol = std::min(newton.floor_rtol, opt.kkt_rtol);
  Start start;
  start.given_u0 = newton.u0;
  start.given_lambda0 = newton.lambda0;
  newton.u0 = newton.lambda0 = nullptr;
  if (opt.nested && has_coarser(spec, opt.nested_min_contact_nodes)) solve_coarser_mesh(spec, opt, R, start, newton);

  const double t0s = wall_time();
  SteklovPoincare S(*R.problem, opt.mg);
  const double t1 = wall_time();
  if (opt.phase_done) opt.phase_done("setup (mesh, operators, multigrid)", t1 - t0s);
  if (opt.iterate_done) show_iterates(S, opt, R, newton);
  ContactConditions law = this_ranks_part(S, R.contact, newton, start);
  choose_initial_iterate(S, opt, law, newton, start, R);
  const bool loose_load = newton.u0 || opt.keep_interior_load;
  const SolveStats cond = scale_of_load(S, opt, newton, start, R);
  const double t2 = wall_time();
  if (opt.phase_done && loose_load)
    opt.phase_done(R.btilde_estimated ? "|b~| (from the coarser mesh, no solve)" : "|b~| (loose condensed load)", t2 - t1);

  if (cond.ok()) {
    solve_contact(S, opt, law, newton, R);
  } else {
    // b̃ is untrustworthy: report instead of iterating on a wrong problem
    const index p = S.contact_nodes();
    R.newton.reason = NewtonReason::inner_failure;
    R.newton.u.assign(3 * p, 0);
    R.newton.lambda.assign(p, 0);
    R.newton.status.assign(p, 0);
  }
  const double t3 = wall_time();
  if (opt.phase_done) opt.phase_done("semismooth* Newton", t3 - t2);

  // the final check's tight residual, warm from Newton's body (or, if
  // Newton did not run, the guess at u0), also recovers the body
  Field<real> body = std::move(start.body);
  if (!R.newton.body.empty()) body = std::move(R.newton.body);
  R.newton.body = {};
  const real check_tolerance = std::max(R.newton.tolerance, opt.kkt_rtol * R.newton.force_scale);
  R.report = final_report(S, law, R.newton, opt.tight_rtol, &body, check_tolerance);
  long long first_check_inner = 0;
  double resumed_seconds = 0;  // (Newton's, in the solve phase)
  const double tr = wall_time();
  if (resume_after_check(S, opt, law, newton, body, tr - t2, R)) {
    resumed_seconds = wall_time() - tr;
    first_check_inner = R.report.inner.iterations;
    body = std::move(R.newton.body);
    R.newton.body = {};
    R.report = final_report(S, law, R.newton, opt.tight_rtol, &body, std::max(check_tolerance, R.newton.tolerance));
    coulomb_consistency(S, opt, law, R);
  }
  gather_contact_values(S, law, R);
  R.contact = std::move(law);
  R.slab = S.slab();
  if (opt.recover_interior) {
    R.u_full = std::move(body);
    S.exchange_ghosts(R.u_full.data());  // its ghost rows too (output pieces)
  }
  // the results are host values (outputs; a coarser mesh's move back)
  R.u_full.move_to(Space::host);
  R.interior_load.move_to(Space::host);
  const double t4 = wall_time();
  if (opt.phase_done) opt.phase_done("final check and recovery", t4 - t3);
  R.times.nested = t0s - t0;
  R.times.setup = t1 - t0s;
  R.times.condense = t2 - t1;
  R.times.solve = t3 - t2 + resumed_seconds;
  R.times.recover = t4 - t3 - resumed_seconds;
  R.times.total = t4 - t0;
  const long long newton_inner = R.coulomb() ? R.coulomb_loop.inner_iterations : R.newton.inner_iterations;
  const long long check_inner = first_check_inner + R.report.inner.iterations;
  R.inner_iterations = cond.iterations + newton_inner + check_inner;
  R.fine_matvecs_total = R.nested_fine_matvecs + R.newton_fine_matvecs() + S.apply_work(cond.iterations) +
                         S.apply_work(check_inner) + R.choice_fine_matvecs;
  R.peak_memory = Comm::world().max(peak_memory_bytes());  // several ranks: the largest rank's
  R.peak_device_memory = launch_on_device() ? block_reuse(Space::device).peak_bytes : 0;

  // A failed Coulomb Newton solve is redone as the fixed point of Tresca
  // solves (each globalised by the line search), and a failed Tresca solve
  // that started from the coarser mesh's solution is redone from x0 = 0
  // (RunOptions::cold_restart); either way the first run's work and time
  // are added to the new run's
  const bool stalled = R.newton.reason == NewtonReason::stagnation || R.newton.reason == NewtonReason::iteration_limit;
  const bool coulomb_failed = stalled && R.coulomb() && opt.friction.method != FrictionLaw::CoulombMethod::fixed_point;
  const bool from_coarse = !opt.newton.u0 && !R.nested.empty() && R.nested.back().converged;
  const bool cold_again = stalled && !R.coulomb() && opt.cold_restart && from_coarse;
  if (!coulomb_failed && !cold_again) return R;
  RunOptions f = opt;
  if (coulomb_failed) {
    f.friction.method = FrictionLaw::CoulombMethod::fixed_point;
    if (opt.phase_done) opt.phase_done("Coulomb: one Newton solve did not converge; again by the fixed point", R.times.total);
  } else {
    f.nested = false;
    if (opt.phase_done) {
      const std::string what = std::string("Newton from the coarser mesh's solution ended ") + to_string(R.newton.reason) +
                               "; again from x0 = 0";
      opt.phase_done(what.c_str(), R.times.total);
    }
  }
  RunResult again = run_tresca(spec, f);
  again.coulomb_fallback = coulomb_failed;
  if (cold_again) {
    again.cold_restart_after = to_string(R.newton.reason);
    again.cold_restart_steps = R.newton.iterations;
    again.nested = std::move(R.nested);  // (solved, and in the work: the report lists them)
  }
  again.fine_matvecs_total += R.fine_matvecs_total;
  again.times.total += R.times.total;
  return again;
}

}  // namespace tresca
