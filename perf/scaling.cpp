// Scaling driver: full tresca solves on chosen levels, each with every thread
// count of --threads (default 1,2), one row per (level, threads):
// dofs, time per phase, Newton / outer / inner iterations, S applications,
// fine-matvec equivalents per Newton step and for the whole solve, those of
// one MG-CG solve of K_ii to 1e-10 on the same mesh and the ratio (a contact
// solve in linear solves), peak memory, speed-up over the first thread count.
// Also as JSON (--json FILE; the run-summary schema plus speedup,
// fine_matvecs_linear_solve, contact_over_linear). A memory estimate is
// printed before each level starts. Exit status 1 if any solve did not converge.
//   build/bin/scaling --levels 4-10 --threads 1,2 --json perf/scaling.json
#include <omp.h>

#include <cstdio>
#include <exception>
#include <sstream>
#include <stdexcept>

#include "core/io/cli.hpp"
#include "core/io/output.hpp"
#include "core/io/summary.hpp"
#include "core/multigrid/interior.hpp"
#include "core/util/profile.hpp"
#include "core/contact/run.hpp"
#include "kernels/simd.hpp"

using namespace tresca;

int main(int argc, char** argv) {
  default_runtime_environment(argv);
  require_one_rank("scaling");
  try {
    Args a(argc, argv, {"--levels", "--threads", "--phi", "--coulomb", "--coulomb-method", "--json"}, {"--help", "--no-nested"});
    if (a.has("--help")) {
      std::puts("usage: scaling [--levels 4-10] [--threads 1,2] [--phi F | --coulomb F [--coulomb-method M]] [--no-nested] [--json FILE]");
      return 0;
    }
    const auto levels = parse_level_range(a.str("--levels", "4-10"));
    std::vector<int> threads;
    {
      std::istringstream is(a.str("--threads", "1,2"));
      std::string t;
      while (std::getline(is, t, ',')) {
        char* end = nullptr;
        const long v = std::strtol(t.c_str(), &end, 10);
        if (t.empty() || *end || v < 1 || v > 1024) throw std::invalid_argument("--threads entry '" + t + "' is not a thread count");
        threads.push_back(int(v));
      }
    }
    const double phi = a.real_value("--phi", 1.0);
    const bool nested = !a.has("--no-nested");
    const FrictionLaw::CoulombMethod method =
        coulomb_method_from(a.str("--coulomb-method", to_string(FrictionLaw{}.method)), "--coulomb-method");
    const FrictionLaw friction = a.has("--coulomb") ? coulomb_friction(a.real_value("--coulomb", 0), method) : tresca_friction();
    const std::string json = a.str("--json");
    if (!json.empty()) check_writable(json);
    for (int L : levels) check_memory(spec_for_level(L));
    std::printf("# kernels: %s\n", build_info().c_str());
    std::printf("# fmv: fine-grid matvec equivalents (the solvers' work counts); fmv K_ii: one MG-CG solve of K_ii to 1e-10\n");
    std::printf("# nested iteration %s; newton, outer, inner, S-app, fmv/step: this mesh; fmv nest: the coarser meshes;\n"
                "# fmv/solve: all of it (coarser meshes, |b~|, Newton, final check and recovery); condense: the loose |b~|\n",
                nested ? "on" : "off (--no-nested)");
    if (friction.is_coulomb())
      std::printf("# Coulomb F = %g: fp = fixed-point iterations (Tresca solves), newton = all their steps\n", friction.F);
    std::printf("%5s %3s %10s %8s %8s %8s %8s %8s %8s %4s %6s %6s %6s %6s %8s %8s %9s %8s %6s %8s %7s\n", "level", "thr",
                "dofs", "nested", "setup", "condense", "solve", "recover", "total", "fp", "newton", "outer", "inner", "S-app",
                "fmv/step", "fmv nest", "fmv/solve", "fmv K_ii", "ratio", "peak GB", "speedup");
    bool all_converged = true;
    Json rows = Json::array();
    for (int L : levels) {
      ProblemSpec s = spec_for_level(L);
      s.phi = phi;
      std::printf("# level %d: mesh %s, estimated memory %.2f GB\n", L, dims_string(s).c_str(),
                  estimated_memory_bytes(s) / 1e9);
      std::fflush(stdout);
      // the price of one linear solve on this mesh, for comparison
      double fmv_linear;
      {
        const Problem P = make_problem(s);
        Multigrid mg(P.grid, P.interior_faces, P.spec.E, P.spec.nu);
        const InteriorSolution lin = solve_interior_elasticity(P, mg, 1e-10);
        fmv_linear = lin.fine_matvecs;
      }
      double t_first = 0;
      for (int T : threads) {
        omp_set_num_threads(T);
        RunOptions o;
        o.recover_interior = true;
        o.nested = nested;
        o.friction = friction;
        const RunResult R = run_tresca(s, o);
        if (T == threads.front()) t_first = R.times.total;
        const double speedup = t_first / R.times.total;
        std::printf("%5d %3d %10lld %8.3f %8.3f %8.3f %8.3f %8.3f %8.3f %4d %6d %6lld %6lld %6lld %8.1f %8.1f %9.1f %8.1f %6.1f %8.2f %7.2f %s\n",
                    L, T, (long long)R.problem->free_dofs(), R.times.nested, R.times.setup, R.times.condense,
                    R.times.solve, R.times.recover, R.times.total, R.coulomb() ? R.coulomb_loop.iterations : 0,
                    int(R.newton_steps()), R.newton.outer_iterations,
                    R.inner_iterations, R.newton.operator_applications, R.fine_matvecs_per_newton_step(),
                    R.nested_fine_matvecs, R.fine_matvecs_total, fmv_linear,
                    R.fine_matvecs_total / fmv_linear, R.peak_memory / 1e9, speedup,
                    R.converged() ? "" : R.reason().c_str());
        all_converged = all_converged && R.converged();
        std::fflush(stdout);
        Json j = run_summary(s, R, T, o);
        j["speedup"] = speedup;
        j["fine_matvecs_linear_solve"] = fmv_linear;
        j["contact_over_linear"] = R.fine_matvecs_total / fmv_linear;
        rows.push_back(std::move(j));
      }
    }
    if (!json.empty()) write_file_atomic(json, json_text(rows));
    if (!all_converged) std::fprintf(stderr, "scaling: some solves did not converge (see the last column)\n");
    return all_converged ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "scaling: error: %s\n", e.what());
    return 2;
  }
}
