// elastic: solve the interior elasticity problem K_ii u = l_i (u = 0 on x = 0
// and on the contact face) with multigrid-preconditioned CG and print a
// summary. The smallest end-to-end check of mesh, kernels and inner solver.
// Under mpirun with several ranks the grid is split into y-slabs and the
// V-cycle is core/parallel/distributed_multigrid.hpp's;
// one rank is the threaded solver of core/fem/interior.hpp.
#include <cstdio>
#include <exception>
#include <string>

#include <cmath>

#include "core/io/cli.hpp"
#include "core/fem/interior.hpp"
#include "core/parallel/distributed_multigrid.hpp"
#include "core/util/profile.hpp"
#include "kernels/vector_ops.hpp"

using namespace tresca;

static const char* kHelp =
    "usage: elastic [--level L | --dims EXxEYxEZ] [--E E] [--nu NU] [--rtol R] [--threads N]\n"
    "Solves K_ii u = l_i of the seed benchmark (clamped at x=0 and on the contact face)\n"
    "with multigrid-preconditioned CG and prints a summary. Default: --level 6 --rtol 1e-10.\n"
    "Under mpirun -np P (P > 1) the mesh is split into P slabs along y.\n";

namespace {

int run_distributed(const ProblemSpec& spec, real rtol, int threads, const Comm& comm) {
  const bool root = comm.rank() == 0;
  const double t0 = wall_time();
  const Problem P = make_problem(spec);  // every rank builds the whole load (phase 2)
  const DistributedMultigrid mg(P.grid, P.interior_faces, spec.E, spec.nu, MGOptions{}, comm);
  const Slab& s = mg.fine_slab();
  const tresca::index n = mg.size();
  std::vector<real> b(n), u(n), r(n);
  global_to_local(s, P.load.data(), b.data());
  zero_constrained(s.local, s.local_faces(P.interior_faces), b.data());
  const LinearOperator& K = mg.op();
  const Comm* reduce = mg.fine_distributed() ? &comm : nullptr;
  if (reduce) static_cast<const DistributedElasticity&>(K).zero_ghosts(b.data());
  comm.barrier();
  const double t1 = wall_time();
  CGOptions o;
  o.rtol = rtol;
  o.comm = reduce;
  CGWorkspace ws;
  const SolveStats st = pcg(K, &mg, b.data(), u.data(), o, ws);
  const double t2 = comm.max(wall_time() - t1);
  // the residual recomputed, over all ranks
  K.apply(u.data(), r.data());
  for (tresca::index i = 0; i < n; ++i) r[i] = b[i] - r[i];
  auto sum = [&](real v) { return reduce ? comm.sum(v) : v; };
  const real rel = std::sqrt(sum(dot(n, r.data(), r.data())) / sum(dot(n, b.data(), b.data())));
  if (reduce) static_cast<const DistributedElasticity&>(K).zero_ghosts(u.data());
  real umax = 0;
  for (real v : u) umax = std::max(umax, std::abs(v));
  umax = real(comm.max(umax));
  const double mem = comm.max(peak_memory_bytes());
  if (root) {
    std::printf("mesh            : %s (level %d)\n", dims_string(spec).c_str(), spec.level);
    std::printf("nodes / dofs    : %lld / %lld\n", (long long)P.nodes(), (long long)P.dofs());
    std::printf("ranks x threads : %d x %d (y-slabs)\n", comm.size(), threads);
    std::printf("multigrid       : %s\n", mg.describe().c_str());
    std::printf("cg              : %s after %d iterations\n", to_string(st.reason), st.iterations);
    std::printf("rel. residual   : %.3e (recomputed)\n", double(rel));
    std::printf("max |u|         : %.6e\n", double(umax));
    std::printf("setup / solve   : %.3f s / %.3f s\n", t1 - t0, t2);
    std::printf("peak memory     : %.3f GB per rank (largest)\n", mem / 1e9);
  }
  return st.ok() ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  default_runtime_environment(argv);
  MpiSession mpi(argc, argv);
  const Comm& comm = Comm::world();
  try {
    Args a(argc, argv, {"--level", "--dims", "--E", "--nu", "--rtol", "--threads"}, {"--help"});
    if (a.has("--help")) {
      if (comm.rank() == 0) std::fputs(kHelp, stdout);
      return 0;
    }
    const int threads = apply_threads(a);
    const ProblemSpec spec = spec_from_args(a, 6);
    const real rtol = a.real_value("--rtol", 1e-10);
    if (!(rtol > 0 && rtol < 1)) throw std::invalid_argument("--rtol " + a.str("--rtol") + " must lie in (0,1)");
    if (comm.distributed()) return run_distributed(spec, rtol, threads, comm);
    const double t0 = wall_time();
    const Problem P = make_problem(spec);
    Multigrid mg(P.grid, P.interior_faces, spec.E, spec.nu);
    const double t1 = wall_time();
    const InteriorSolution sol = solve_interior_elasticity(P, mg, rtol);
    const SolveStats& st = sol.stats;
    real umax = 0;
    for (real v : sol.u) umax = std::max(umax, std::abs(v));
    std::printf("mesh            : %s (level %d)\n", dims_string(spec).c_str(), spec.level);
    std::printf("nodes / dofs    : %lld / %lld\n", (long long)P.nodes(), (long long)P.dofs());
    std::printf("threads         : %d\n", threads);
    std::printf("multigrid       : %s\n", mg.describe().c_str());
    std::printf("cg              : %s after %d iterations\n", to_string(st.reason), st.iterations);
    std::printf("rel. residual   : %.3e (recomputed)\n", sol.relative_residual);
    std::printf("max |u|         : %.6e\n", umax);
    std::printf("setup / solve   : %.3f s / %.3f s\n", t1 - t0, sol.seconds);
    return st.ok() ? 0 : 1;
  } catch (const std::exception& e) {
    if (comm.rank() == 0) std::fprintf(stderr, "elastic: error: %s\n", e.what());
    return 2;
  }
}
