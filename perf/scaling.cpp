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

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <exception>
#include <sstream>
#include <stdexcept>

#include "core/io/cli.hpp"
#include "core/io/output.hpp"
#include "core/io/summary.hpp"
#include "core/multigrid/interior.hpp"
#include "core/util/profile.hpp"
#include "core/contact/run.hpp"
#include "kernels/isa.hpp"

using namespace tresca;

namespace {
// "1,2,4" -> {1, 2, 4}, each in 1..1024
std::vector<int> parse_counts(const std::string& text, const char* option) {
  std::vector<int> out;
  std::istringstream is(text);
  std::string t;
  while (std::getline(is, t, ',')) {
    char* end = nullptr;
    const long v = std::strtol(t.c_str(), &end, 10);
    if (t.empty() || *end || v < 1 || v > 1024)
      throw std::invalid_argument(std::string(option) + " entry '" + t + "' is not a count in 1..1024");
    out.push_back(int(v));
  }
  if (out.empty()) throw std::invalid_argument(std::string(option) + " is empty");
  return out;
}

// Rank scaling: each (level, R) solved by `mpirun -np R ... tresca` with one
// thread per rank, its time read from that run's JSON; the bandwidth-ideal
// speed-up is the triad's with R threads in this process (the same cores'
// bandwidth). Open MPI's mpirun (its -x and --bind-to).
bool rank_rows(const std::vector<int>& levels, const std::vector<int>& ranks, long long repeat,
               const std::string& solver_args, const std::string& mpirun, Json& rows) {
  char self[4096];
  const ssize_t len = readlink("/proc/self/exe", self, sizeof self - 1);
  if (len <= 0) throw std::runtime_error("cannot find this program's directory (/proc/self/exe)");
  self[len] = 0;
  const std::string tresca_bin = std::filesystem::path(self).parent_path() / "tresca";
  const long cores = sysconf(_SC_NPROCESSORS_ONLN);
  std::vector<double> triad;
  for (int R : ranks) {
    omp_set_num_threads(R);
    triad.push_back(triad_bandwidth(tresca::index(1) << 24, 5));
  }
  std::printf("# ranks: %s -np R %s --level L %s (1 OpenMP thread per rank)\n", mpirun.c_str(), tresca_bin.c_str(),
              solver_args.c_str());
  std::printf("# STREAM triad with R threads in this process (the bandwidth R ranks share):");
  for (size_t k = 0; k < ranks.size(); ++k) std::printf(" %d: %.1f GB/s", ranks[k], triad[k] / 1e9);
  std::printf("\n%5s %5s %10s %9s %7s %8s %5s %s\n", "level", "ranks", "dofs", "total", "speedup", "bw-ideal", "eff",
              repeat > 1 ? "[min-max] newton" : "newton");
  const std::string json_path = (std::filesystem::temp_directory_path() / ("scaling_ranks_" + std::to_string(getpid()) + ".json")).string();
  bool all_converged = true;
  for (int L : levels) {
    double t_first = 0;
    for (size_t k = 0; k < ranks.size(); ++k) {
      const int R = ranks[k];
      const std::string bind = R <= cores ? "--bind-to core" : "--oversubscribe --bind-to none";
      const std::string cmd = mpirun + " -np " + std::to_string(R) + " " + bind + " -x OMP_NUM_THREADS=1 " + tresca_bin +
                              " --level " + std::to_string(L) + " --quiet " + solver_args + " --json " + json_path + " 2>&1";
      std::vector<double> totals;
      Json last;
      for (long long rep = 0; rep < repeat; ++rep) {
        std::remove(json_path.c_str());
        std::string out;
        FILE* p = popen(cmd.c_str(), "r");
        if (!p) throw std::runtime_error("cannot start: " + cmd);
        char buf[4096];
        size_t n;
        while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
        const int st = pclose(p);
        if (!std::filesystem::exists(json_path))
          throw std::runtime_error("'" + cmd + "' wrote no JSON (exit status " + std::to_string(st) + "):\n" + out);
        last = Json::parse(read_text_file(json_path, "the run's JSON"));
        totals.push_back(last["times"]["total"].get<double>());
        all_converged = all_converged && last["converged"].get<bool>();
      }
      std::remove(json_path.c_str());
      std::vector<double> sorted = totals;
      std::sort(sorted.begin(), sorted.end());
      const double total = sorted[(sorted.size() - 1) / 2];
      if (k == 0) t_first = total;
      const double speedup = t_first / total, bw_ideal = triad[k] / triad.front();
      std::printf("%5d %5d %10lld %9.3f %7.2f %8.2f %5.2f", L, R, last["dofs"].get<long long>(), total, speedup, bw_ideal,
                  speedup / bw_ideal);
      if (repeat > 1) std::printf(" [%.3f-%.3f]", sorted.front(), sorted.back());
      std::printf(" %d%s\n", last["newton_iterations"].get<int>(), last["converged"].get<bool>() ? "" : " NOT CONVERGED");
      std::fflush(stdout);
      rows.push_back({{"level", L}, {"ranks", R}, {"threads_per_rank", 1}, {"total_seconds", total},
                      {"total_seconds_runs", totals}, {"speedup", speedup}, {"triad_bytes_per_second", triad[k]},
                      {"bandwidth_ideal_speedup", bw_ideal}, {"efficiency", speedup / bw_ideal},
                      {"newton_iterations", last["newton_iterations"]}, {"converged", last["converged"]}});
    }
  }
  return all_converged;
}
}  // namespace

static const char* kHelp =
    "usage: scaling [--levels A-B] [--threads 1,2,... | --ranks 1,2,... [--mpirun CMD]] [--repeat N]\n"
    "               [--phi F | --coulomb F [--coulomb-method M]] [--no-nested] [--json FILE]\n"
    "Whole contact solves on each level A..B with each thread count, one row per (level, threads):\n"
    "times per phase, Newton / outer / inner iterations, S applications, fine-grid matvec\n"
    "equivalents (fmv) per Newton step and per solve, against one MG-CG solve of K_ii to 1e-10\n"
    "on the same mesh, peak memory, the speed-up over the first thread count, the bandwidth-ideal\n"
    "speed-up (the STREAM triad's ratio, measured at start with each thread count) and the\n"
    "efficiency (speed-up / bandwidth-ideal: 1 = as fast as the memory allows).\n"
    "  --levels A-B       mesh levels (default 4-10)\n"
    "  --threads T1,T2    thread counts (default 1,2)\n"
    "  --ranks R1,R2      MPI rank counts instead, one thread each: every solve is `mpirun -np R\n"
    "                     tresca ...` (Open MPI; --mpirun CMD, default mpirun), its time read from\n"
    "                     its JSON; the bandwidth-ideal speed-up is the triad's with R threads\n"
    "  --repeat N         solve each (level, threads) N times (default 1); the row is the run of\n"
    "                     median total time, with the range of the N totals beside it\n"
    "  --phi F            Tresca friction bound (default 1)\n"
    "  --coulomb F        Coulomb friction instead;  --coulomb-method newton|lagged|fixed-point\n"
    "  --no-nested        start every Newton from x0 = 0 on its own mesh\n"
    "  --json FILE        the rows as JSON (the run-summary schema plus speedup, repeats,\n"
    "                     total_seconds_runs, fine_matvecs_linear_solve, contact_over_linear,\n"
    "                     triad_bytes_per_second, bandwidth_ideal_speedup, efficiency)\n"
    "  -h, --help         this text;  --version  the version and the build (ISA, compiler)\n"
    "Exit status: 0 all converged, 1 some did not, 2 bad input.\n";

int main(int argc, char** argv) {
  require_one_rank("scaling");
  try {
    Args a(argc, argv, {"--levels", "--threads", "--ranks", "--mpirun", "--repeat", "--phi", "--coulomb", "--coulomb-method", "--json"},
           {"--no-nested"});
    if (answered_help_or_version(a, "scaling", kHelp)) return 0;
    const auto levels = parse_level_range(a.str("--levels", "4-10"));
    const std::vector<int> threads = parse_counts(a.str("--threads", "1,2"), "--threads");
    const long long repeat = a.int_value("--repeat", 1);
    if (repeat < 1 || repeat > 1000) throw std::invalid_argument("--repeat " + a.str("--repeat") + " must be in 1..1000");
    const double phi = a.real_value("--phi", 1.0);
    const bool nested = !a.has("--no-nested");
    const FrictionLaw::CoulombMethod method =
        coulomb_method_from(a.str("--coulomb-method", to_string(FrictionLaw{}.method)), "--coulomb-method");
    const FrictionLaw friction = a.has("--coulomb") ? coulomb_friction(a.real_value("--coulomb", 0), method) : tresca_friction();
    const std::string json = a.str("--json");
    if (!json.empty()) check_writable(json);
    for (int L : levels) check_memory(spec_for_level(L));
    warn_if_cores_busy();
    std::printf("# kernels: %s\n", build_info().c_str());
    if (a.has("--ranks")) {
      if (a.has("--threads")) throw std::invalid_argument("--ranks and --threads: one sweep at a time");
      std::ostringstream args;
      args << "--phi " << phi << (nested ? "" : " --no-nested");
      if (friction.is_coulomb())
        args << " --coulomb " << friction.F << " --coulomb-method " << to_string(friction.method);
      Json rows = Json::array();
      const bool ok = rank_rows(levels, parse_counts(a.str("--ranks"), "--ranks"), repeat, args.str(),
                                a.str("--mpirun", "mpirun"), rows);
      if (!json.empty()) write_file_atomic(json, json_text(rows));
      if (!ok) std::fprintf(stderr, "scaling: some solves did not converge (see the last column)\n");
      return ok ? 0 : 1;
    }
    // the machine's own bandwidth with each thread count, measured now: a
    // bandwidth-bound solve can speed up by the triad's ratio at most
    std::vector<double> triad;
    for (int T : threads) {
      omp_set_num_threads(T);
      triad.push_back(triad_bandwidth(tresca::index(1) << 24, 5));
    }
    std::printf("# STREAM triad (3 x 128 MiB, best of 5) with");
    for (size_t k = 0; k < threads.size(); ++k) std::printf(" %d: %.1f GB/s%s", threads[k], triad[k] / 1e9, k + 1 < threads.size() ? "," : "\n");
    std::printf("# speedup: over the first thread count; bw-ideal: the triad's ratio; eff: speedup / bw-ideal;\n"
                "# 1-thread: seconds of the total outside parallel regions (no thread count shortens them)\n");
    std::printf("# fmv: fine-grid matvec equivalents (the solvers' work counts); fmv K_ii: one MG-CG solve of K_ii to 1e-10\n");
    std::printf("# nested iteration %s; newton, outer, inner, S-app, fmv/step: this mesh; fmv nest: the coarser meshes;\n"
                "# fmv/solve: all of it (coarser meshes, |b~|, Newton, final check and recovery); condense: the loose |b~|\n",
                nested ? "on" : "off (--no-nested)");
    if (friction.is_coulomb())
      std::printf("# Coulomb F = %g: fp = fixed-point iterations (Tresca solves), newton = all their steps\n", friction.F);
    std::printf("%5s %3s %10s %8s %8s %8s %8s %8s %8s %4s %6s %6s %6s %6s %8s %8s %9s %8s %6s %8s %7s", "level", "thr",
                "dofs", "nested", "setup", "condense", "solve", "recover", "total", "fp", "newton", "outer", "inner", "S-app",
                "fmv/step", "fmv nest", "fmv/solve", "fmv K_ii", "ratio", "peak GB", "speedup");
    std::printf(" %8s %5s %8s\n", "bw-ideal", "eff", "1-thread");
    if (repeat > 1)
      std::printf("# each row: the median of %lld solves by total time; [min-max] of their totals after it\n", repeat);
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
      for (size_t k = 0; k < threads.size(); ++k) {
        const int T = threads[k];
        omp_set_num_threads(T);
        RunOptions o;
        o.recover_interior = true;
        o.nested = nested;
        o.friction = friction;
        // every repetition's row and summary; the median's are kept
        std::vector<double> totals, serial;
        std::vector<std::string> lines, reasons;
        std::vector<Json> summaries;
        for (long long rep = 0; rep < repeat; ++rep) {
          profile_reset();  // each run's profile its own
          const RunResult R = run_tresca(s, o);
          char line[512];
          std::snprintf(line, sizeof line,
                        "%5d %3d %10lld %8.3f %8.3f %8.3f %8.3f %8.3f %8.3f %4d %6d %6lld %6lld %6lld %8.1f %8.1f %9.1f %8.1f %6.1f %8.2f",
                        L, T, (long long)R.problem->free_dofs(), R.times.nested, R.times.setup, R.times.condense,
                        R.times.solve, R.times.recover, R.times.total, R.coulomb() ? R.coulomb_loop.iterations : 0,
                        int(R.newton_steps()), R.newton.outer_iterations, R.inner_iterations,
                        R.newton.operator_applications, R.fine_matvecs_per_newton_step(), R.nested_fine_matvecs,
                        R.fine_matvecs_total, fmv_linear, R.fine_matvecs_total / fmv_linear, R.peak_memory / 1e9);
          lines.push_back(line);
          reasons.push_back(R.converged() ? "" : " " + R.reason());
          all_converged = all_converged && R.converged();
          Json j = run_summary(s, R, T, o);
          j["fine_matvecs_linear_solve"] = fmv_linear;
          j["contact_over_linear"] = R.fine_matvecs_total / fmv_linear;
          summaries.push_back(std::move(j));
          totals.push_back(R.times.total);
          serial.push_back(one_thread_seconds(R.times.total));
        }
        std::vector<size_t> order(totals.size());
        for (size_t i = 0; i < order.size(); ++i) order[i] = i;
        std::sort(order.begin(), order.end(), [&](size_t x, size_t y) { return totals[x] < totals[y]; });
        const size_t med = order[(order.size() - 1) / 2];
        const double total = totals[med];
        if (T == threads.front()) t_first = total;
        const double speedup = t_first / total, bw_ideal = triad[k] / triad.front();
        char tail[96];
        std::snprintf(tail, sizeof tail, " %7.2f %8.2f %5.2f %8.3f", speedup, bw_ideal, speedup / bw_ideal, serial[med]);
        std::string range;
        if (repeat > 1) {
          char r[64];
          std::snprintf(r, sizeof r, " [%.3f-%.3f]", totals[order.front()], totals[order.back()]);
          range = r;
        }
        std::printf("%s%s%s%s\n", lines[med].c_str(), tail, range.c_str(), reasons[med].c_str());
        std::fflush(stdout);
        Json j = summaries[med];
        j["speedup"] = speedup;
        j["triad_bytes_per_second"] = triad[k];
        j["bandwidth_ideal_speedup"] = bw_ideal;
        j["efficiency"] = speedup / bw_ideal;
        j["repeats"] = repeat;
        j["total_seconds_runs"] = totals;
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
