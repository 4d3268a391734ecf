// mpi_apply: the distributed matrix-free apply and a distributed CG on
// slabs of the grid (issue 12, phase 1), against the communication model.
//
//   mpirun --bind-to core -np 2 -x OMP_NUM_THREADS=1 build/bin/mpi_apply --level 11
//   mpirun --bind-to none -np 1 -x OMP_NUM_THREADS=2 build/bin/mpi_apply --level 11
//
// Prints per rank count: M dof/s of the halo exchange and y = K x, and of
// the apply alone, the halo messages and bytes per apply measured
// against comm_model.hpp, the time blocked waiting for them, and a
// Jacobi-preconditioned CG on K (u = 0 on x = 0 and on the contact face,
// the seed load) to --rtol: iterations and time, the same on any rank count.
// --project L,R: the model's weak-scaling projection of an MG-CG iteration
// to R ranks at level L (assumed network: --latency, --bandwidth; compute
// per rank: --rate, the apply's dof/s).
#include <omp.h>

#include <cmath>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "core/io/cli.hpp"
#include "core/fem/problem.hpp"
#include "core/parallel/comm.hpp"
#include "core/parallel/comm_model.hpp"
#include "core/fem/elasticity_operator.hpp"
#include "core/solvers/cg.hpp"
#include "core/multigrid/multigrid.hpp"
#include "core/util/profile.hpp"
#include "kernels/isa.hpp"
#include "kernels/vector_ops.hpp"

using namespace tresca;

static const char* kHelp =
    "usage: mpi_apply [--level L | --dims EXxEYxEZ] [--reps N] [--rtol R] [--max-iterations N] [--threads N]\n"
    "                 [--project LEVEL,RANKS] [--latency S] [--bandwidth B/s] [--rate DOF/s] [--outer N] [--inner N]\n"
    "The distributed elasticity apply and a Jacobi-CG on y-slabs, one per MPI rank (default --level 8).\n"
    "Run it with mpirun -np P; --project prints the communication model's projection instead.\n"
    "  --level L | --dims EXxEYxEZ  the mesh (default --level 8)\n"
    "  --reps N           applies timed (default 20)\n"
    "  --rtol R           relative residual of the Jacobi-CG (default 1e-6)\n"
    "  --max-iterations N its iteration limit (default 20000)\n"
    "  --threads N        OpenMP threads per rank (default: OMP_NUM_THREADS or all cores)\n"
    "  --project L,P      the model's time per apply and per MG-CG iteration at level L on P ranks\n"
    "  --latency S, --bandwidth B/s, --rate DOF/s  the network and node model of --project\n"
    "  --outer N, --inner N   Newton's outer and inner iterations the projection multiplies\n"
    "  -h, --help         this text;  --version  the version and the build (ISA, compiler)\n";

namespace {

int project(const Args& a) {
  const std::string s = a.str("--project");
  const auto sp = s.find(',');
  if (sp == std::string::npos) throw std::invalid_argument("--project '" + s + "' must be LEVEL,RANKS");
  const ProblemSpec spec = spec_for_level(std::stoll(s.substr(0, sp)));
  const int ranks = int(std::stoll(s.substr(sp + 1)));
  if (ranks < 1) throw std::invalid_argument("--project: ranks must be >= 1");
  NetworkModel net;
  net.latency = a.real_value("--latency", net.latency);
  net.bandwidth = a.real_value("--bandwidth", net.bandwidth);
  const GridDims g = grid_of(spec);
  const auto H = GridHierarchy::build(g, MGOptions{}.coarse_nodes);
  int px = 1, py = 1;
  rank_grid(g, ranks, px, py);
  const CommVolume ap = apply_halo(g, px, py), it = mgcg_iteration(H->grids(), px, py, MGOptions{}.degree);
  std::printf("level %d: mesh %s, %.3g dofs, %d ranks as %d x %d boxes, %.3g dofs per rank\n", spec.level,
              dims_string(spec).c_str(), double(spec.free_dofs()), ranks, px, py, double(spec.free_dofs()) / ranks);
  std::printf("network assumed: latency %.2g s, bandwidth %.3g GB/s per rank\n", net.latency, net.bandwidth / 1e9);
  std::printf("apply:        %6.0f messages %10.4g bytes  -> %.3g s\n", ap.messages, ap.bytes, net.seconds(ap, ranks));
  std::printf("MG-CG iter.:  %6.0f messages %10.4g bytes %3.0f allreduces -> %.3g s\n", it.messages, it.bytes,
              it.allreduces, net.seconds(it, ranks));
  // compute per rank at --rate dof/s of the apply (default: one core of
  // this machine, perf/RESULTS.md §0g); an MG-CG iteration is one apply and
  // a V-cycle of about (2 degree + 2) applies per level, weighted by size
  const double rate = a.real_value("--rate", 2.5e8), per_rank = double(spec.free_dofs()) / ranks;
  double cycle = 0;
  for (const GridDims& l : H->grids()) cycle += (2 * MGOptions{}.degree + 2) * double(l.nodes()) / double(g.nodes());
  const double t_apply = per_rank / rate, t_it = (1 + cycle) * t_apply;
  std::printf("compute at %.3g dof/s per rank: apply %.3g s, MG-CG iteration %.3g s (%.1f applies)\n", rate, t_apply,
              t_it, 1 + cycle);
  std::printf("communication share without overlap: apply %.1f %%, MG-CG iteration %.1f %%\n",
              100 * net.seconds(ap, ranks) / (t_apply + net.seconds(ap, ranks)),
              100 * net.seconds(it, ranks) / (t_it + net.seconds(it, ranks)));
  // a Newton step with the counts measured at levels 10-12 (--outer per
  // step, --inner per S apply; perf/RESULTS.md §0g)
  const double outer = a.real_value("--outer", 3.5), inner = a.real_value("--inner", 6);
  const CommVolume st = newton_step_comm(H->grids(), px, py, MGOptions{}.degree, outer, inner);
  const double t_step = ((outer + 2) * (inner * (1 + cycle) + 2.0 / double(g.nz())) + outer * cycle) * t_apply;
  std::printf("Newton step (%.1f outer, %.0f inner per S apply): %.0f messages %10.4g bytes %.0f allreduces -> %.3g s "
              "against %.3g s of compute (%.1f %%)\n",
              outer, inner, st.messages, st.bytes, st.allreduces, net.seconds(st, ranks), t_step,
              100 * net.seconds(st, ranks) / (t_step + net.seconds(st, ranks)));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  MpiSession mpi(argc, argv);
  const Comm& comm = Comm::world();
  try {
    Args a(argc, argv,
           {"--level", "--dims", "--reps", "--rtol", "--max-iterations", "--threads", "--project", "--latency", "--bandwidth", "--rate", "--outer", "--inner"},
           {});
    if (answered_help_or_version(a, "mpi_apply", kHelp)) return 0;
    const int threads = apply_threads(a);
    if (a.has("--project")) return comm.rank() == 0 ? project(a) : 0;
    const ProblemSpec spec = spec_from_args(a, 8);
    const int reps = int(a.int_value("--reps", 20));
    const real rtol = a.real_value("--rtol", 1e-6);
    const int max_it = int(a.int_value("--max-iterations", 20000));
    if (reps < 1) throw std::invalid_argument("--reps must be >= 1");
    warn_if_cores_busy();
    const GridDims g = grid_of(spec);
    const Slab slab = make_slab(g, comm.rank(), comm.size());
    const Problem P = make_problem(spec);  // every rank builds the global load (phase 1)
    const ElasticityOperator K(slab, P.interior_faces, spec.E, spec.nu);
    const tresca::index n = K.size();
    std::vector<real> x(n), y(n);
    for (tresca::index i = 0; i < n; ++i) x[i] = std::sin(0.001 * double(i + slab.y_begin));
    if (comm.rank() == 0)
      std::printf("mpi_apply: mesh %s (%s), %lld dofs, %d ranks x %d threads, y-slabs; kernels: %s\n",
                  dims_string(spec).c_str(), spec.level >= 0 ? ("level " + std::to_string(spec.level)).c_str() : "dims",
                  (long long)P.dofs(), comm.size(), threads, build_info().c_str());
    const double dofs = double(P.dofs());
    double rate[2], wait = 0;
    const HaloCounts before = K.halo_counts();
    for (int exchange = 1; exchange >= 0; --exchange) {
      const HaloCounts c0 = K.halo_counts();
      K.update_ghosts(x.data());  // warm-up
      K.apply(x.data(), y.data());
      double best = 1e300;
      for (int r = 0; r < reps; ++r) {
        comm.barrier();
        const double t0 = wall_time();
        if (exchange) K.update_ghosts(x.data());
        K.apply(x.data(), y.data());
        best = std::min(best, comm.max(wall_time() - t0));
      }
      rate[exchange] = dofs / best;
      if (exchange) wait = comm.max(K.halo_counts().wait_seconds - c0.wait_seconds) / (reps + 1);
    }
    const HaloCounts c = K.halo_counts();
    const double applies = double(c.exchanges - before.exchanges);
    const CommVolume model = slab_apply_halo(g, int(slab.lo + slab.hi));
    const double msg = applies > 0 ? (c.messages - before.messages) / applies : 0;
    const double bytes = applies > 0 ? (c.bytes - before.bytes) / applies : 0;
    if (comm.rank() == 0) {
      std::printf("apply: %.1f M dof/s with the halo exchange, %.1f M dof/s the apply alone (best of %d, slowest rank)\n",
                  rate[1] / 1e6, rate[0] / 1e6, reps);
      std::printf("halo per apply (rank 0): %.0f messages, %.0f bytes; model %.0f, %.0f; blocked in MPI_Waitall %.3g ms "
                  "per exchange (slowest rank)\n",
                  msg, bytes, model.messages, model.bytes, wait * 1e3);
    }
    // Jacobi-CG on the slab: the same iterations and answer on any rank count
    const Field<real> load = load_on(P, slab);
    std::vector<real> b(load.begin(), load.end()), u(n, 0.0);
    zero_constrained(slab.local, slab.local_faces(P.interior_faces), b.data());
    K.zero_ghosts(b.data());
    const JacobiPreconditioner J(K);
    CGOptions o;
    o.rtol = rtol;
    o.max_iterations = max_it;
    o.reduction = &comm;
    CGWorkspace ws;
    comm.barrier();
    const double t0 = wall_time();
    const SolveStats st = pcg(K, &J, b.data(), u.data(), o, ws);
    const double t = comm.max(wall_time() - t0);
    K.zero_ghosts(u.data());
    const real unorm = std::sqrt(comm.sum(dot(n, u.data(), u.data())));
    const double mem = comm.max(peak_memory_bytes());
    if (comm.rank() == 0)
      std::printf("Jacobi-CG to %.1e: %s after %d iterations, %.3f s (%.2f ms per iteration), |u| = %.12e; peak memory per rank %.3f GB\n",
                  double(rtol), to_string(st.reason), st.iterations, t, 1e3 * t / std::max(1, st.iterations),
                  double(unorm), mem / 1e9);
    return st.ok() || st.reason == SolveReason::max_iterations ? 0 : 1;  // a capped run is a measurement
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mpi_apply: %s\n", e.what());
    return 2;
  }
}
