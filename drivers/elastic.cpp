// elastic: solve the interior elasticity problem K_ii u = l_i (u = 0 on x = 0
// and on the contact face) with multigrid-preconditioned CG and print a
// summary. The smallest end-to-end check of mesh, kernels and inner solver.
// Under mpirun with several ranks the grid is split into y-slabs
// (core/multigrid/multigrid.hpp); the solve is core/multigrid/interior.hpp's.
#include <cstdio>
#include <exception>
#include <string>

#include <cmath>

#include "core/io/cli.hpp"
#include "core/multigrid/interior.hpp"
#include "core/util/profile.hpp"

using namespace tresca;

static const char* kHelp =
    "usage: elastic [--level L | --dims EXxEYxEZ] [--E E] [--nu NU] [--rtol R] [--threads N] [--device D]\n"
    "Solves K_ii u = l_i of the seed benchmark (clamped at x=0 and on the contact face)\n"
    "with multigrid-preconditioned CG and prints a summary. Default: --level 6 --rtol 1e-10.\n"
    "Under mpirun -np P (P > 1) the mesh is split into P slabs along y.\n"
    "  --level L          mesh level (default 6): ex = ceil(4*2^(L/2)), ey = ez = ceil(2*2^(L/2))\n"
    "  --dims EXxEYxEZ    explicit element counts instead of a level\n"
    "  --E E, --nu NU     material (default 2.1e9 Pa, 0.277)\n"
    "  --rtol R           relative residual of the CG solve (default 1e-10, in (0,1))\n"
    "  --threads N        OpenMP threads (default: OMP_NUM_THREADS or all cores)\n"
    "  --device cpu|gpu   where the kernels run (default cpu); gpu: every operator, multigrid\n"
    "                     level and CG vector in the GPU's memory (a -DTRESCA_OFFLOAD=ON build)\n"
    "  -h, --help         this text;  --version  the version and the build (ISA, compiler)\n"
    "Exit status: 0 converged (the residual recomputed from u within 2 rtol), 1 not converged, 2 bad input.\n";

int main(int argc, char** argv) {
  MpiSession mpi(argc, argv);
  const Comm& comm = Comm::world();
  try {
    Args a(argc, argv, {"--level", "--dims", "--E", "--nu", "--rtol", "--threads", "--device"}, {});
    if (answered_help_or_version(a, "elastic", kHelp)) return 0;
    const int threads = apply_threads(a);
    const std::string device = apply_device(a, comm);  // (before the spec: its memory check knows a device run)
    const ProblemSpec spec = spec_from_args(a, 6);
    const real rtol = a.real_value("--rtol", 1e-10);
    if (!(rtol > 0 && rtol < 1)) throw std::invalid_argument("--rtol " + a.str("--rtol") + " must lie in (0,1)");
    warn_if_cores_busy();
    const double t0 = wall_time();
    const Problem P = make_problem(spec);  // every rank builds the whole load
    MGOptions mo;
    const std::string why_double = keep_vcycles_in_range(spec, mo);
    if (!why_double.empty() && comm.rank() == 0) std::fprintf(stderr, "elastic: note: %s\n", why_double.c_str());
    const Multigrid mg(P.grid, P.interior_faces, spec.E, spec.nu, mo, comm);
    comm.barrier();
    const double t1 = wall_time();
    const InteriorSolution sol = solve_interior_elasticity(P, mg, rtol);
    const SolveStats& st = sol.stats;
    const double solve = comm.max(sol.seconds), mem = comm.max(peak_memory_bytes());
    // converged: the residual recomputed from the solution meets rtol too
    // (within a factor 2: CG's running residual drifts from the true one by
    // rounding, and below the true one's floor it goes on falling)
    const bool reached = st.ok() && sol.relative_residual <= 2 * rtol;
    if (comm.rank() == 0) {
      std::printf("mesh            : %s (level %d)\n", dims_string(spec).c_str(), spec.level);
      std::printf("nodes / dofs    : %lld / %lld\n", (long long)P.nodes(), (long long)P.dofs());
      std::printf("ranks x threads : %d x %d (%s)\n", comm.size(), threads, rank_layout(P.grid, comm, "rank 0 solves the whole mesh").c_str());
      std::printf("kernels on      : %s\n", device.c_str());
      std::printf("multigrid       : %s\n", mg.describe().c_str());
      if (st.ok() && !reached)
        std::printf("cg              : not converged after %d iterations: its running residual met rtol %.1e, the "
                    "recomputed one did not (rtol below what double precision resolves here)\n",
                    st.iterations, double(rtol));
      else
        std::printf("cg              : %s after %d iterations\n", to_string(st.reason), st.iterations);
      std::printf("rel. residual   : %.3e (recomputed)\n", double(sol.relative_residual));
      std::printf("max |u|         : %.6e\n", double(sol.max_abs_u));
      std::printf("setup / solve   : %.3f s / %.3f s\n", t1 - t0, solve);
      std::printf("peak memory     : %.3f GB%s\n", mem / 1e9, comm.distributed() ? " per rank (largest)" : "");
    }
    return reached ? 0 : 1;
  } catch (const std::exception& e) {
    if (comm.rank() == 0) std::fprintf(stderr, "elastic: error: %s\n", e.what());
    return 2;
  }
}
