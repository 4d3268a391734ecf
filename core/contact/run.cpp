#include "core/contact/run.hpp"

#include <string>

#include "core/contact/nested.hpp"
#include "kernels/vector_ops.hpp"
#include "core/util/profile.hpp"

namespace tresca {

RunResult run_tresca(const ProblemSpec& spec, const RunOptions& opt) {
  RunResult R;
  const double t0 = wall_time();
  R.problem = std::make_unique<Problem>(make_problem(spec));
  R.contact = opt.contact.phi.empty()
                  ? ContactConditions::uniform(R.problem->contact_nodes(), spec.phi, spec.gap)
                  : opt.contact;
  // nested iteration: the coarser mesh first (before this mesh's operators
  // exist, so the peak memory stays this mesh's), its (u, lambda) carried here
  NewtonOptions newton = opt.newton;
  std::vector<real> u0, lambda0;
  double nested_work = 0;
  if (opt.nested && !newton.u0 && has_coarser(spec, opt.nested_min_contact_nodes)) {
    const ProblemSpec cs = coarser_spec(spec);
    RunOptions co = opt;
    co.recover_interior = false;
    co.newton.progress = nullptr;
    co.newton.rtol = opt.nested_rtol;
    co.final_check = false;
    co.contact = coarse_conditions(*R.problem, R.contact, make_problem(cs));
    const RunResult C = run_tresca(cs, co);
    R.nested = C.nested;
    R.nested.push_back({cs, C.newton.iterations, C.newton.converged(), C.fine_matvecs_total, C.times.total});
    nested_work = C.fine_matvecs_total * double(cs.free_dofs()) / double(spec.free_dofs());
    if (opt.phase_done) {
      const std::string what = "nested: mesh " + std::to_string(cs.ex) + "x" + std::to_string(cs.ey) + "x" +
                               std::to_string(cs.ez) + ", " + std::to_string(C.newton.iterations) + " Newton steps" +
                               (C.newton.converged() ? "" : " (not converged: not used)");
      opt.phase_done(what.c_str(), C.times.total);
    }
    if (C.newton.converged()) {
      prolongate_contact(*C.problem, C.newton.u, C.newton.lambda, *R.problem, u0, lambda0);
      newton.u0 = &u0;
      newton.lambda0 = &lambda0;
    }
  }
  const double t0s = wall_time();
  SteklovPoincare S(*R.problem, opt.mg);
  const double t1 = wall_time();
  if (opt.phase_done) opt.phase_done("setup (mesh, operators, multigrid)", t1 - t0s);
  std::vector<real> btilde;
  std::vector<real> interior_load;  // K_ii^{-1} l_i, for the recovery
  const SolveStats cond = S.condensed_load(opt.tight_rtol, btilde, opt.recover_interior ? &interior_load : nullptr);
  const double t2 = wall_time();
  if (opt.phase_done) opt.phase_done("condensed load", t2 - t1);
  if (!cond.ok()) {
    // b̃ is untrustworthy: report instead of iterating on a wrong problem
    const index p = R.problem->contact_nodes();
    R.newton.reason = NewtonReason::inner_failure;
    R.newton.u.assign(3 * p, 0);
    R.newton.lambda.assign(p, 0);
    R.newton.status.assign(p, 0);
  } else {
    R.newton = semismooth_newton(S, btilde, R.contact, newton);
  }
  const double t3 = wall_time();
  if (opt.phase_done) opt.phase_done("semismooth* Newton", t3 - t2);
  // the final check's tight S u also gives E u: u = E u + K_ii^{-1} l_i
  if (opt.final_check) {
    R.report = final_report(S, btilde, R.contact, R.newton, opt.tight_rtol, opt.recover_interior ? &R.u_full : nullptr);
    if (opt.recover_interior) axpy(index(R.u_full.size()), 1, interior_load.data(), R.u_full.data());
  }
  const double t4 = wall_time();
  if (opt.phase_done) opt.phase_done("final check and recovery", t4 - t3);
  R.times.nested = t0s - t0;
  R.times.setup = t1 - t0s;
  R.times.condense = t2 - t1;
  R.times.solve = t3 - t2;
  R.times.recover = t4 - t3;
  R.times.total = t4 - t0;
  R.inner_iterations = cond.iterations + R.newton.inner_iterations + R.report.inner.iterations;
  R.fine_matvecs_total =
      nested_work + R.newton.fine_matvecs + S.apply_work(cond.iterations) + S.apply_work(R.report.inner.iterations);
  R.peak_memory = peak_memory_bytes();
  return R;
}

}  // namespace tresca
