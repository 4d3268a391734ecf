#include "core/io/summary.hpp"

#include "core/util/profile.hpp"

#include "core/parallel/comm.hpp"

#include <cmath>

#include "core/io/cli.hpp"
#include "core/io/output.hpp"
#include "core/io/problem_file.hpp"
#include "kernels/launch.hpp"
#include "kernels/isa.hpp"

namespace tresca {

namespace {
Json dims_json(const ProblemSpec& s) { return Json::array({s.ex, s.ey, s.ez}); }
}  // namespace

Json run_summary(const ProblemSpec& spec, const RunResult& R, int threads, const RunOptions& opt) {
  const double eps = opt.newton.eps;
  const Problem& P = *R.problem;
  const FinalReport& F = R.report;
  const NewtonResult& N = R.newton;
  Json nested = Json::array();
  for (const NestedLevel& l : R.nested)
    nested.push_back({{"dims", dims_json(l.spec)},
                      {"newton_iterations", l.newton_iterations},
                      {"converged", l.converged},
                      {"fine_matvecs_own", l.fine_matvecs},
                      {"seconds", l.seconds},
                      {"device", l.on_device ? "gpu" : "cpu"}});
  const Obstacle& o = spec.obstacle;
  Json obstacle = {{"kind", to_string(o.kind)}, {"gap", o.gap}};
  if (o.kind == Obstacle::Kind::plane) {
    obstacle["slope_x"] = o.slope_x;
    obstacle["slope_y"] = o.slope_y;
  } else {
    obstacle["radius"] = o.radius;
    obstacle["cx"] = o.cx;
    obstacle["cy"] = o.cy;
  }
  Json coulomb = nullptr;
  if (R.coulomb()) {
    const CoulombResult& C = R.coulomb_loop;
    coulomb = {{"F", R.friction.F},
               {"method", to_string(opt.friction.method)},
               {"fallback_to_fixed_point", R.coulomb_fallback},
               {"fixed_point_iterations", C.iterations},
               {"reason", to_string(C.reason)},
               {"converged", C.converged()},
               {"changes", C.changes},
               {"newton_steps", C.newton_steps},
               {"consistency", R.coulomb_consistency}};
  }
  Json j;
  j["level"] = spec.level >= 0 ? Json(spec.level) : Json(nullptr);
  j["dims"] = dims_json(spec);
  j["nodes"] = P.nodes();
  j["contact_nodes"] = P.contact_nodes();
  j["dofs"] = P.free_dofs();
  j["friction"] = R.coulomb() ? "coulomb" : "tresca";
  j["phi"] = R.coulomb() ? Json(nullptr) : Json(spec.phi);
  j["gap"] = spec.obstacle.gap;
  j["obstacle"] = obstacle;
  j["load_scale"] = spec.load_scale;
  j["eps"] = eps;
  j["threads"] = threads;  // per rank
  j["ranks"] = Comm::world().size();
  j["rank_layout"] = run_rank_layout(spec);
  if (Comm::world().distributed()) {  // what rank 0 sent over the whole run (comm.hpp)
    const CommCounters& c = comm_counters();
    j["communication_rank0"] = {{"messages", c.messages}, {"bytes", c.bytes}, {"allreduces", c.allreduces},
                                {"collectives", c.collectives}};
  }
  j["build"] = build_info();
  j["device"] = launch_on_device() ? "gpu, " + device_description() : std::string("cpu");
  j["omp_wait"] = omp_wait_setting();
  j["huge_pages"] = huge_page_setting();
  {
    const ThreadPlacement t = thread_placement();
    j["placement"] = {{"thread_cpus", t.thread_cpus},
                      {"cpus", t.cpus},
                      {"omp_proc_bind", t.proc_bind.empty() ? Json(nullptr) : Json(t.proc_bind)},
                      {"omp_places", t.places.empty() ? Json(nullptr) : Json(t.places)}};
  }
  j["mg_precision"] = to_string(opt.mg.precision);
  j["newton_iterations"] = N.iterations;
  j["converged"] = R.converged();
  j["reason"] = R.reason();
  j["initial_iterate"] = R.initial_iterate.empty() ? Json(nullptr) : Json(R.initial_iterate);
  j["cold_restart"] = R.cold_restart_after.empty()
                          ? Json(nullptr)
                          : Json{{"after", R.cold_restart_after}, {"newton_iterations", R.cold_restart_steps}};
  j["stopping_rule"] = N.stop == StopRule::consistent ? "consistent" : "paper";
  j["tolerance"] = N.tolerance;
  j["residual_floor"] = N.residual_floor;  // > 0: converged at this level of what r resolves, above eps [N]
  j["floor_measured"] = N.floor_measured;  // > 0: |r warm - r cold| there, where the floor was above 1e-10 |b~| [N]
  j["residual_history"] = N.history;
  j["step_lengths"] = N.step_lengths;
  j["inner_iterations_history"] = N.inner_history;
  j["outer_iterations_history"] = N.outer_history;
  j["final_residual"] = N.history.empty() ? Json(nullptr) : Json(N.history.back());
  j["true_residual"] = F.true_residual;
  j["true_residual_relative"] = F.true_residual_relative;
  j["btilde_norm"] = F.btilde_norm;  // |b̃| [N], the scale of the relative figures
  j["btilde_estimated"] = R.btilde_estimated;  // from the coarser mesh's interior solve (about 1 %)
  j["true_residual_within_eps"] = F.true_residual <= eps;
  j["true_residual_resolution"] = F.resolution;  // r is known to about this [N]
  // the kernel profile of the run (core/util/profile.hpp; shares of the total add up to 1 with "other")
  Json profile = Json::array();
  for (const ProfileRow& r : profile_rows(R.times.total))
    profile.push_back({{"kernel", r.kernel},
                       {"calls", r.calls},
                       {"seconds", r.seconds},
                       {"self_seconds", r.self_seconds},
                       {"share", r.share},
                       {"bytes_per_s", r.bytes_per_s},
                       {"flops_per_s", r.flops_per_s},
                       {"parallel", r.parallel}});
  j["profile"] = profile;
  // every kernel's launches (kernels/launch.hpp, launches_by_kernel), the longest first
  Json kernels = Json::array();
  for (const KernelLaunches& k : kernel_launches_since_reset())
    kernels.push_back({{"kernel", k.kernel},
                       {"where", to_string(k.ran)},
                       {"calls", k.calls},
                       {"seconds", k.seconds},
                       {"bytes", k.bytes},
                       {"flops", k.flops}});
  j["kernels"] = kernels;
  // the launches of the run (kernels/launch.hpp): what ran threaded, what on one thread
  const LaunchCounts L = launches_since_reset();
  Json by_size = Json::array();
  for (int k = 0; k < LaunchCounts::kSizes; ++k)
    by_size.push_back({{"regions", L.by_size[k]}, {"seconds", L.by_size_seconds[k]}, {"work", L.by_size_work[k]}});
  j["launches"] = {{"parallel_regions", L.threaded},
                   {"one_thread", L.one_thread},
                   {"device", L.device},
                   {"threaded_seconds", L.threaded_seconds},
                   {"one_thread_launch_seconds", L.one_thread_seconds},
                   {"device_seconds", L.device_seconds},
                   {"one_thread_seconds", one_thread_seconds(R.times.total)},
                   {"by_work", by_size}};
  j["times"] = {{"nested", R.times.nested}, {"setup", R.times.setup},   {"condense", R.times.condense},
                {"solve", R.times.solve},   {"recover", R.times.recover}, {"total", R.times.total}};
  j["counts"] = {{"inner_iterations", R.inner_iterations},
                 {"outer_iterations", N.outer_iterations},
                 {"operator_applications", N.operator_applications},
                 {"newton_inner_iterations", N.inner_iterations},
                 {"outer_limit_hits", N.outer_limit_hits},
                 {"watchdog_steps", N.watchdog_steps},
                 {"envelope_steps", N.envelope_steps},
                 {"redone_steps", N.redone_steps},
                 {"monotone_from", N.monotone_from},
                 {"resumed_from", R.resumed_from},
                 {"last_state_changes", N.last_state_changes},
                 {"inner_tightening", N.inner_tightening},
                 {"fine_matvecs_per_newton_step", R.fine_matvecs_per_newton_step()},
                 {"fine_matvecs_solve", R.newton_fine_matvecs()},
                 {"fine_matvecs_total", R.fine_matvecs_total}};
  j["contact"] = {{"active", F.active},   {"separated", F.separated}, {"sticking", F.sticking}, {"sliding", F.sliding},
                  {"ux_min", F.ux_min},   {"uz_max", F.uz_max},       {"lambda_sum", F.lambda_sum}};
  j["kkt"] = {{"equilibrium", F.equilibrium},         {"uz_violation", F.uz_violation},
              {"lambda_violation", F.lambda_violation}, {"complementarity", F.complementarity},
              {"friction_bound", F.friction_bound},   {"friction_direction", F.friction_direction},
              {"stick_slip", F.stick_slip},           {"largest_in_newtons", F.kkt_force},
              {"residual_consistent", F.true_residual_consistent}, {"tolerance", F.tolerance},
              {"slip_unresolved", F.slip_unresolved}, {"ok", F.kkt_ok}};
  j["problem"] = Json::parse(problem_json(spec, R.friction));
  j["nested"] = nested;
  j["coulomb"] = coulomb;
  j["peak_memory_bytes"] = R.peak_memory;
  j["peak_device_bytes"] = R.peak_device_memory;
  return j;
}

}  // namespace tresca
