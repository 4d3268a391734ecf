// Scaling driver: full tresca solves on chosen levels, each with every thread
// count of --threads (default 1,2), one row per (level, threads):
// dofs, time per phase, Newton / outer / inner iterations, S applications,
// fine-matvec equivalents per Newton step, peak memory, speed-up over the
// first thread count. Also as JSON (--json FILE). A memory estimate is printed
// before each level starts.
//   build/bin/scaling --levels 4-10 --threads 1,2 --json perf/scaling.json
#include <omp.h>

#include <cstdio>
#include <exception>
#include <sstream>
#include <stdexcept>

#include "core/io/cli.hpp"
#include "core/io/output.hpp"
#include "core/io/summary.hpp"
#include "core/util/profile.hpp"
#include "core/contact/run.hpp"
#include "kernels/simd.hpp"

using namespace tresca;

int main(int argc, char** argv) {
  default_wait_policy(argv);
  try {
    Args a(argc, argv, {"--levels", "--threads", "--phi", "--json"}, {"--help"});
    if (a.has("--help")) {
      std::puts("usage: scaling [--levels 4-10] [--threads 1,2] [--phi F] [--json FILE]");
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
    const std::string json = a.str("--json");
    if (!json.empty()) check_writable(json);
    for (int L : levels) check_memory(spec_for_level(L));
    std::printf("# kernels: %s\n", build_info().c_str());
    std::printf("%5s %3s %10s %8s %8s %8s %8s %8s %6s %6s %6s %6s %8s %8s %7s\n", "level", "thr", "dofs", "setup",
                "condense", "solve", "recover", "total", "newton", "outer", "inner", "S-app", "fmv/step", "peak GB",
                "speedup");
    std::string rows = "[";
    for (int L : levels) {
      ProblemSpec s = spec_for_level(L);
      s.phi = phi;
      std::printf("# level %d: mesh %s, estimated memory %.2f GB\n", L, dims_string(s).c_str(),
                  estimated_memory_bytes(s) / 1e9);
      std::fflush(stdout);
      double t_first = 0;
      for (int T : threads) {
        omp_set_num_threads(T);
        RunOptions o;
        o.recover_interior = true;
        const RunResult R = run_tresca(s, o);
        if (T == threads.front()) t_first = R.times.total;
        const double speedup = t_first / R.times.total;
        std::printf("%5d %3d %10lld %8.3f %8.3f %8.3f %8.3f %8.3f %6d %6lld %6lld %6lld %8.1f %8.2f %7.2f %s\n", L, T,
                    (long long)R.problem->free_dofs(), R.times.setup, R.times.condense, R.times.solve, R.times.recover,
                    R.times.total, R.newton.iterations, R.newton.outer_iterations, R.inner_iterations,
                    R.newton.operator_applications, R.fine_matvecs_per_newton_step(), R.peak_memory / 1e9, speedup,
                    R.newton.converged() ? "" : to_string(R.newton.reason));
        std::fflush(stdout);
        Json j = run_summary(s, R, T, o);
        j.num("speedup", speedup);
        rows += (rows.size() > 1 ? ",\n " : "") + j.render();
      }
    }
    if (!json.empty()) write_file_atomic(json, rows + "]\n");
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "scaling: error: %s\n", e.what());
    return 2;
  }
}
