#include "core/io/summary.hpp"

#include <cmath>

#include "core/io/output.hpp"
#include "core/io/problem_file.hpp"
#include "kernels/simd.hpp"

namespace tresca {

namespace {
std::string dims_json(const ProblemSpec& s) {
  return "[" + std::to_string(s.ex) + ", " + std::to_string(s.ey) + ", " + std::to_string(s.ez) + "]";
}
}  // namespace

Json run_summary(const ProblemSpec& spec, const RunResult& R, int threads, const RunOptions& opt) {
  const double eps = opt.newton.eps;
  const Problem& P = *R.problem;
  const FinalReport& F = R.report;
  const NewtonResult& N = R.newton;
  Json times, counts, contact, kkt;
  times.num("nested", R.times.nested).num("setup", R.times.setup).num("condense", R.times.condense).num("solve", R.times.solve)
      .num("recover", R.times.recover).num("total", R.times.total);
  counts.integer("inner_iterations", R.inner_iterations).integer("outer_iterations", N.outer_iterations)
      .integer("operator_applications", N.operator_applications)
      .integer("newton_inner_iterations", N.inner_iterations)
      .integer("outer_limit_hits", N.outer_limit_hits)
      .num("fine_matvecs_per_newton_step", R.fine_matvecs_per_newton_step())
      .num("fine_matvecs_solve", R.newton_fine_matvecs()).num("fine_matvecs_total", R.fine_matvecs_total);
  contact.integer("active", F.active).integer("separated", F.separated).integer("sticking", F.sticking)
      .integer("sliding", F.sliding).num("ux_min", F.ux_min).num("uz_max", F.uz_max).num("lambda_sum", F.lambda_sum);
  kkt.num("equilibrium", F.equilibrium).num("uz_violation", F.uz_violation).num("lambda_violation", F.lambda_violation)
      .num("complementarity", F.complementarity).num("friction_bound", F.friction_bound)
      .num("friction_direction", F.friction_direction).num("stick_slip", F.stick_slip);
  std::string nested = "[";
  for (const NestedLevel& l : R.nested) {
    Json n;
    n.raw("dims", dims_json(l.spec))
        .integer("newton_iterations", l.newton_iterations).boolean("converged", l.converged)
        .num("fine_matvecs_own", l.fine_matvecs).num("seconds", l.seconds);
    nested += (nested.size() > 1 ? ", " : "") + n.render();
  }
  nested += "]";
  Json obstacle;
  {
    const Obstacle& o = spec.obstacle;
    obstacle.str("kind", to_string(o.kind)).num("gap", o.gap);
    if (o.kind == Obstacle::Kind::plane)
      obstacle.num("slope_x", o.slope_x).num("slope_y", o.slope_y);
    else
      obstacle.num("radius", o.radius).num("cx", o.cx).num("cy", o.cy);
  }
  Json coulomb;
  if (R.coulomb) {
    const CoulombResult& C = R.coulomb_loop;
    coulomb.num("F", opt.coulomb)
        .str("method", opt.coulomb_method == RunOptions::CoulombMethod::lagged ? "lagged" : "fixed_point")
        .boolean("fallback_to_fixed_point", R.coulomb_fallback)
        .integer("fixed_point_iterations", C.iterations)
        .str("reason", to_string(C.reason)).boolean("converged", C.converged()).array("changes", C.changes)
        .integer("newton_steps", C.newton_steps).num("consistency", R.coulomb_consistency);
  }
  Json j;
  if (spec.level >= 0)
    j.integer("level", spec.level);
  else
    j.null("level");
  j.raw("dims", dims_json(spec))
      .integer("nodes", P.nodes()).integer("contact_nodes", P.contact_nodes()).integer("dofs", P.free_dofs())
      .str("friction", R.coulomb ? "coulomb" : "tresca")
      .num("phi", R.coulomb ? NAN : spec.phi).num("gap", spec.obstacle.gap).raw("obstacle", obstacle.render()).num("load_scale", spec.load_scale).num("eps", eps).integer("threads", threads).str("build", build_info())
      .str("mg_precision", to_string(opt.mg.precision)).integer("newton_iterations", N.iterations)
      .boolean("converged", R.converged()).str("reason", R.reason())
      .array("residual_history", N.history)
      .array("inner_iterations_history", std::vector<double>(N.inner_history.begin(), N.inner_history.end()))
      .array("outer_iterations_history", std::vector<double>(N.outer_history.begin(), N.outer_history.end())).num("final_residual", N.history.empty() ? NAN : N.history.back())
      .num("true_residual", F.true_residual).num("true_residual_relative", F.true_residual_relative)
      .boolean("true_residual_within_eps", F.true_residual <= eps)
      .raw("times", times.render()).raw("counts", counts.render()).raw("contact", contact.render())
      .raw("kkt", kkt.render()).raw("problem", problem_json(spec, R.coulomb ? opt.coulomb : -1)).raw("nested", nested).raw("coulomb", R.coulomb ? coulomb.render() : "null").num("peak_memory_bytes", R.peak_memory);
  return j;
}


}  // namespace tresca
