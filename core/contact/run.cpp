#include "core/contact/run.hpp"

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
  SteklovPoincare S(*R.problem, opt.mg);
  const double t1 = wall_time();
  if (opt.phase_done) opt.phase_done("setup (mesh, operators, multigrid)", t1 - t0);
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
    R.newton = semismooth_newton(S, btilde, R.contact, opt.newton);
  }
  const double t3 = wall_time();
  if (opt.phase_done) opt.phase_done("semismooth* Newton", t3 - t2);
  // the final check's tight S u also gives E u: u = E u + K_ii^{-1} l_i
  R.report = final_report(S, btilde, R.contact, R.newton, opt.tight_rtol, opt.recover_interior ? &R.u_full : nullptr);
  if (opt.recover_interior) axpy(index(R.u_full.size()), 1, interior_load.data(), R.u_full.data());
  const double t4 = wall_time();
  if (opt.phase_done) opt.phase_done("final check and recovery", t4 - t3);
  R.times = {t1 - t0, t2 - t1, t3 - t2, t4 - t3, t4 - t0};
  R.inner_iterations = cond.iterations + R.newton.inner_iterations + R.report.inner.iterations;
  R.fine_matvecs_total = R.newton.fine_matvecs + S.apply_work(cond.iterations) + S.apply_work(R.report.inner.iterations);
  R.peak_memory = peak_memory_bytes();
  return R;
}

}  // namespace tresca
