// One complete solve of the contact problem, with the timings of the paper's
// Table 1 columns: setup (mesh, operators, multigrid hierarchy), condense
// (|b̃| by a loose solve, only when Newton starts from an initial iterate:
// from x0 = 0 the condensed load is Newton's first residual -b̃), solve
// (semismooth* Newton, which keeps r = S u - b̃ and the body), recover
// (final check: r by one tight solve warm from Newton's body, which is then
// the body's displacement u = E u_c + K_ii^{-1} l_i).
#pragma once
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/contact/coulomb.hpp"
#include "core/contact/friction.hpp"
#include "core/contact/report.hpp"
#include "core/contact/semismooth.hpp"
#include "core/parallel/slab.hpp"

namespace tresca {

// One coarse mesh of a nested run: what its solve took.
struct NestedLevel {
  ProblemSpec spec;
  int newton_iterations = 0;
  bool converged = false;
  double fine_matvecs = 0;  // its own work (without coarser meshes), in matvecs of that mesh
  double seconds = 0;       // its own time (without coarser meshes)
  bool on_device = false;   // where its launches ran (device_min_nodes(), kernels/launch.hpp)
};

// One Newton iterate of the fine mesh with the body's displacement, for
// output (RunOptions::iterate_done); pointers valid during the call. The
// progress's contact vectors hold every contact node, on every rank.
struct Iterate {
  const Problem* problem;
  int step;  // 0, 1, ... over the run (a Coulomb fixed point's Tresca solves continue it)
  const NewtonProgress* progress;
  const Field<real>* u_full;        // 3N SoA: E u + K_ii^{-1} l_i (several ranks: on `slab`, ghost rows current)
  const std::vector<real>* gap;     // p
  const Slab* slab;                 // the rank's rows of u_full (one rank: the whole grid)
};

struct RunOptions {
  NewtonOptions newton;
  MGOptions mg;  // both V-cycles: the inner K_ii solve and the Newton-step preconditioner
  // called after each phase with its name and duration (progress on long runs)
  std::function<void(const char* phase, double seconds)> phase_done;
  // called after each coarse mesh of nested iteration, coarsest first
  std::function<void(const NestedLevel&)> nested_done;
  bool recover_interior = true;  // full 3D displacement (needed for VTK output)
  // called at every Newton iterate of the fine mesh with the body's
  // displacement (one extra solve per iterate, to 1e-8, not counted as
  // solver work); for output such as --vtk-every-iteration
  std::function<void(const Iterate&)> iterate_done;
  // nested iteration (nested.hpp): coarser meshes first, down to meshes of
  // at least nested_min_contact_nodes contact nodes (has_coarser); off:
  // x0 = 0 (the paper). 16, not 64: 28 % fewer fine matvecs on the random
  // problems whose chain it lengthens, as many converged (perf/RESULTS.md
  // §0zw)
  bool nested = true;
  index nested_min_contact_nodes = 16;
  // the coarse meshes stop at |v̂| <= nested_rtol |v̂_0| (their solutions
  // differ from the fine one by the discretisation error anyway) and
  // compute r = S u - b̃ to 1e-3 nested_rtol (chosen by measurement:
  // perf/RESULTS.md §0i)
  real nested_rtol = 1e-3;
  // the coarse meshes' Newton iteration limit: this factor times the
  // finest mesh's (NewtonOptions::max_iterations). A coarse mesh's step
  // costs about an eighth of the next finer one's (a half on a bar one
  // element wide and thick), and a coarse mesh that
  // converges hands up an iterate near the solution: two plates and a
  // cantilever whose coarse meshes converged at steps 52-63 ended at the
  // finest mesh's limit of 50 from a cold start instead (perf/RESULTS.md
  // §0zv). Applied once: the coarse meshes of a coarse mesh get the same.
  int nested_iteration_factor = 4;
  // a Tresca run whose Newton started from the coarser mesh's solution and
  // ended in stagnation or at the iteration limit is solved again from
  // x0 = 0 (RunResult::cold_restart_after): on slender plates and bars a
  // coarse solution can be a start from which Newton creeps where x0 = 0
  // converges (perf/RESULTS.md §0zw). The finest mesh only: a coarse
  // mesh that fails is not used.
  bool cold_restart = true;
  real tight_rtol = 1e-12;
  // the final check's verdict: KKT in consistent units within
  // max(Newton's tolerance, kkt_rtol |b̃|) (100 times what the check resolves)
  real kkt_rtol = 1e-10;
  // |b̃| (the scale of the absolute accuracies) of a run with an initial
  // iterate, by a solve to this relative accuracy
  real scale_rtol = 1e-3;
  // set on a coarser mesh of nested iteration: keep K_ii^{-1} l_i (to
  // scale_rtol) as the finer mesh's guess for its |b̃|
  bool keep_interior_load = false;
  // the contact law per node (p values each); empty: contact_conditions(spec)
  ContactConditions contact;
  // Tresca (the bounds of `contact` / spec.phi) or Coulomb (friction.hpp;
  // contact.phi and spec.phi are then not used). If one Coulomb Newton solve
  // fails, the fixed point takes over (run.cpp).
  FrictionLaw friction;
  real coulomb_tol = 1e-6;  // the fixed point's stop on the relative change of phi (coarse meshes: nested_rtol)
};


struct RunTimes {
  double nested = 0;  // the coarser meshes' solves of nested iteration
  double setup = 0, condense = 0, solve = 0, recover = 0, total = 0;
};

// Everything in it is host values, wherever the launches ran (--device gpu:
// the solve's Fields are copied out at its end).
struct RunResult {
  std::unique_ptr<Problem> problem;
  RunTimes times;
  NewtonResult newton;        // the (last) Tresca solve
  ContactConditions contact;  // the law used at each contact node (Coulomb: the last bound F lambda)
  FrictionLaw friction;  // the run's (RunOptions::friction; the fixed point after a fallback)
  bool coulomb() const { return friction.is_coulomb(); }
  // Coulomb: the fixed point's account (its `last` moved into newton)
  CoulombResult coulomb_loop;
  bool coulomb_fallback = false;  // one Newton solve failed; the fixed point took over
  real coulomb_consistency = 0;  // max_i |phi_i - F lambda_i| at the solution [N]
  // converged: Newton's test, the Coulomb fixed point's, and the final
  // check's KKT verdict (report.hpp) all say so
  bool converged() const { return newton.converged() && (!coulomb() || coulomb_loop.converged()) && report.kkt_ok; }
  std::string reason() const {
    if (!newton.converged()) return to_string(newton.reason);
    if (coulomb() && !coulomb_loop.converged()) return to_string(coulomb_loop.reason);
    return report.kkt_ok ? "converged" : "kkt_check_failed";
  }
  FinalReport report;
  Field<real> u_full;               // 3N SoA (empty if not recovered); several ranks: slab's local vector
  Slab slab;                        // the rank's rows of u_full (one rank: the whole grid)
  Field<real> interior_load;        // K_ii^{-1} l_i to scale_rtol, 3N SoA (keep_interior_load only)
  // |b̃| (newton.force_scale, report.btilde_norm) from the coarser mesh's
  // K_ii^{-1} l_i without a solve (the finest mesh of nested iteration): to
  // about 1 %, not to scale_rtol
  bool btilde_estimated = false;
  long long inner_iterations = 0;  // over the whole run, including condensation and the final check
  // work in fine-grid matvec equivalents (the Newton phase alone is
  // newton.fine_matvecs): the whole run, |b̃|, Newton and the final tight
  // check (which includes the recovery)
  double fine_matvecs_total = 0;
  double peak_memory = 0;  // bytes, process peak resident set after the run (several ranks: the largest)
  double peak_device_memory = 0;  // bytes, the most the device's Fields held so far (a device run; else 0)
  // the coarse meshes of nested iteration, coarsest first (empty: cold start);
  // fine_matvecs_total includes their work, scaled by their share of the dofs
  std::vector<NestedLevel> nested;
  double nested_fine_matvecs = 0;  // their work in this mesh's matvecs
  // with a given initial iterate and nested iteration: which one Newton
  // started from ("given" or "coarser mesh", the smaller merit |w|), and
  // the two residuals that decided it (included in fine_matvecs_total)
  std::string initial_iterate;
  double choice_fine_matvecs = 0;
  // a stop the final check did not confirm: the Newton step it went on
  // from, and the eps it went on to (run.cpp: resume_after_check); -1: none
  int resumed_from = -1;
  real resumed_eps = 0;
  // RunOptions::cold_restart: how Newton from the coarser mesh's solution
  // ended before the run was solved again from x0 = 0, and its steps (their
  // work and time are in the totals); empty: no such restart
  std::string cold_restart_after;
  int cold_restart_steps = 0;
  long long newton_steps() const { return coulomb() ? coulomb_loop.newton_steps : newton.iterations; }
  double newton_fine_matvecs() const { return coulomb() ? coulomb_loop.fine_matvecs : newton.fine_matvecs; }
  double fine_matvecs_per_newton_step() const {
    return newton_steps() > 0 ? newton_fine_matvecs() / double(newton_steps()) : 0;
  }
};

// spec.phi at every contact node, and the gap to spec.obstacle under it
ContactConditions contact_conditions(const ProblemSpec& spec);

RunResult run_tresca(const ProblemSpec& spec, const RunOptions& opt);
// how run_tresca's ranks hold the mesh of spec (multigrid.hpp: rank_layout;
// a mesh too small to split is solved whole by every rank)
std::string run_rank_layout(const ProblemSpec& spec);
// the memory estimate of one of run_tresca's ranks (problem.hpp), with the
// mesh split as it will be
double run_memory_per_rank(const ProblemSpec& spec);

}  // namespace tresca
