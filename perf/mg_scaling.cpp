// Inner-solver scaling: MG-preconditioned CG for K_ii to a relative residual
// of 1e-10 on levels A..B; one row per level, plus --json FILE.
//   OMP_NUM_THREADS=2 build/bin/mg_scaling --levels 3-11
#include <cstdio>
#include <exception>

#include "core/io/cli.hpp"
#include "core/multigrid/interior.hpp"
#include "core/io/output.hpp"
#include "core/util/profile.hpp"
#include "kernels/isa.hpp"

using namespace tresca;

static const char* kHelp =
    "usage: mg_scaling [--levels A-B] [--rtol R] [--threads N] [--precision single|double] [--json FILE]\n"
    "The inner solver alone: multigrid-preconditioned CG for K_ii u = l_i on each level A..B,\n"
    "one row per level (dofs, V-cycle levels, iterations, setup and solve time, dof/s).\n"
    "  --levels A-B       mesh levels (default 3-11)\n"
    "  --rtol R           relative residual (default 1e-10, in (0,1))\n"
    "  --threads N        OpenMP threads (default: OMP_NUM_THREADS or all cores)\n"
    "  --precision single|double  arithmetic of the V-cycles (default single)\n"
    "  --json FILE        the rows as JSON\n"
    "  -h, --help         this text;  --version  the version and the build (ISA, compiler)\n";

int main(int argc, char** argv) {
  require_one_rank("mg_scaling");
  try {
    Args a(argc, argv, {"--levels", "--rtol", "--threads", "--json", "--precision"}, {});
    if (answered_help_or_version(a, "mg_scaling", kHelp)) return 0;
    MGOptions mo;
    const std::string prec = a.str("--precision", "single");
    if (prec != "single" && prec != "double")
      throw std::invalid_argument("--precision '" + prec + "' must be single or double");
    mo.precision = prec == "single" ? Precision::single_precision : Precision::double_precision;
    const int threads = apply_threads(a);
    const auto levels = parse_level_range(a.str("--levels", "3-11"));
    const real rtol = a.real_value("--rtol", 1e-10);
    if (!(rtol > 0 && rtol < 1)) throw std::invalid_argument("--rtol must lie in (0,1)");
    const std::string json = a.str("--json");
    if (!json.empty()) check_writable(json);
    for (int L : levels) check_memory(spec_for_level(L));
    warn_if_cores_busy();
    std::printf("# kernels: %s, %d threads\n", build_info().c_str(), threads);
    std::printf("%5s %11s %-70s %6s %9s %9s %11s %s\n", "level", "dofs", "hierarchy", "iters", "setup[s]", "solve[s]",
                "s/iter", "rel.res (recomputed)");
    Json rows = Json::array();
    bool all_ok = true;
    for (int L : levels) {
      const Problem P = make_problem(spec_for_level(L));
      const double t0 = wall_time();
      Multigrid mg(P.grid, P.interior_faces, P.spec.E, P.spec.nu, mo);
      const double t1 = wall_time();
      const InteriorSolution sol = solve_interior_elasticity(P, mg, rtol);
      const SolveStats& st = sol.stats;
      const double solve = sol.seconds, rel = sol.relative_residual;
      std::printf("%5d %11lld %-70s %6d %9.3f %9.3f %11.4f %.2e %s\n", L, (long long)P.dofs(), mg.describe().c_str(),
                  st.iterations, t1 - t0, solve, solve / std::max(1, st.iterations), rel,
                  st.ok() ? "" : to_string(st.reason));
      std::fflush(stdout);
      all_ok = all_ok && st.ok();
      rows.push_back({{"level", L},
                      {"dofs", P.dofs()},
                      {"levels", mg.num_levels()},
                      {"iterations", st.iterations},
                      {"setup", t1 - t0},
                      {"solve", solve},
                      {"relative_residual", rel},
                      {"reason", to_string(st.reason)},
                      {"threads", threads},
                      {"build", build_info()},
                      {"precision", to_string(mo.precision)}});
    }
    if (!json.empty()) write_file_atomic(json, json_text(rows));
    if (!all_ok) std::fprintf(stderr, "mg_scaling: some solves did not converge (see the last column)\n");
    return all_ok ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mg_scaling: error: %s\n", e.what());
    return 2;
  }
}
