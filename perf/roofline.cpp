// Each kernel against this machine's own limits, in one run.
//
// First the machine: streaming bandwidth by the STREAM triad a = b + s c
// (arrays far larger than the caches, first-touch placement by the same
// threads), reported as STREAM counts it (24 bytes per entry) and as the
// traffic it really causes (32 bytes: writing a also reads it into cache,
// write-allocate). The latter is the bound used below, because in-place
// updates (axpy, cg_update) move exactly their modelled bytes. Then the flop peak of the build's vectors
// (independent FMA chains in registers, the vectors of the kernels' instruction set, kernels/isa.hpp).
// Then every kernel on the fields of mesh level L, timed best of several
// repetitions, with its modelled bytes and flops (the Cost constants in the
// kernel headers). A kernel's roofline bound is max(bytes / triad, flops /
// peak); "of bound" is that bound over the measured time (100 % = at the
// roof). Output: one aligned table, and with --json FILE the same as JSON.
// With --device gpu (an offload build) the same on the device: every field
// in its memory, the triad measured there (a GPU writes whole lines without
// reading them, so the bound is the STREAM count itself), and no flop peak
// (the bound is the bandwidth's).
//   OMP_NUM_THREADS=2 build/bin/roofline --level 10 --json roofline.json
#include <omp.h>

#include <algorithm>
#include <cstdio>
#include <exception>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "core/io/cli.hpp"
#include "core/multigrid/multigrid.hpp"
#include "core/io/output.hpp"
#include "core/fem/problem.hpp"
#include "core/util/profile.hpp"
#include "kernels/boundary_block.hpp"
#include "kernels/contact_maps.hpp"
#include "kernels/elasticity.hpp"
#include "kernels/isa.hpp"
#include "kernels/transfer.hpp"
#include "kernels/vector_ops.hpp"

using namespace tresca;

namespace {

double best_of(int reps, const std::function<void()>& f) {
  f();  // warm-up: page faults, caches
  return best_time(reps, f);
}

// peak flop/s of T on every thread: kFmaChains independent FMA chains of
// the vectors of the kernels' instruction set (kernels/isa.hpp)
template <class T>
double fma_peak(long iterations) {
  const IsaKernels& v = isa();
  double (*chains)(long) = sizeof(T) == sizeof(float) ? v.fma_chains_f : v.fma_chains_d;
  double sink = 0;
  const double t = best_of(3, [&] { sink += chains(iterations); });
  if (!(sink > 0)) std::fprintf(stderr, "roofline: FMA check failed\n");
  const int lanes = v.vector_bytes / int(sizeof(T));
  return 2.0 * kFmaChains * lanes * double(iterations) * omp_get_max_threads() / t;
}

const char* kHelp =
    "usage: roofline [--level L] [--threads N] [--reps R] [--json FILE] [--device cpu|gpu]\n"
    "This machine's limits (STREAM triad bandwidth, FMA peak) and every kernel on the fields\n"
    "of mesh level L against them: time, items/s, GB/s and GFLOP/s from the kernels' modelled\n"
    "bytes and flops, and the fraction of the roofline bound max(bytes/BW, flops/peak).\n"
    "Where a level's vectors fit in the caches (the triad over three of them beats the memory\n"
    "triad by 25 %), the run says so: those GB/s are cache bandwidth, above 100 % of BW.\n"
    "  --level L          mesh level of the fields (default 10)\n"
    "  --threads N        OpenMP threads (default: OMP_NUM_THREADS or all cores)\n"
    "  --reps R           repetitions per kernel, the best one kept (default 20)\n"
    "  --json FILE        the same as one JSON object\n"
    "  --device cpu|gpu   where the kernels and their fields are (default cpu; gpu: an offload\n"
    "                     build, measured against the device's own triad, no flop peak)\n"
    "  -h, --help         this text;  --version  the version and the build (ISA, compiler)\n";

struct Row {
  std::string name;
  double items, seconds;
  Cost cost;  // total for one call
  bool single;  // float data: compared with the float FMA peak
};

}  // namespace

int main(int argc, char** argv) {
  require_one_rank("roofline");
  try {
    Args a(argc, argv, {"--level", "--threads", "--reps", "--json", "--device"}, {});
    if (answered_help_or_version(a, "roofline", kHelp)) return 0;
    const int threads = apply_threads(a);
    const std::string device = apply_device(a, Comm::self());
    const bool on_device = launch_on_device();
    const long long level = a.int_value("--level", 10);
    const long long reps = a.int_value("--reps", 20);
    if (reps < 1 || reps > 100000) throw std::invalid_argument("--reps " + a.str("--reps") + " must be in 1..100000");
    const ProblemSpec spec = spec_for_level(level);
    check_memory(spec);
    const std::string json = a.str("--json");
    if (!json.empty()) check_writable(json);

    warn_if_cores_busy();
    const double stream = triad_bandwidth(tresca::index(1) << 25, int(std::min(reps, 10LL)));
    const double bw = on_device ? stream : stream * 32.0 / 24.0;  // (CPU: with the write-allocate read of a)
    const double none = std::numeric_limits<double>::infinity();  // no flop bound
    const double peak = on_device ? none : fma_peak<double>(20000000);
    const double peak_single = on_device ? none : fma_peak<float>(20000000);
    std::printf("# %s, %d threads; kernels on %s\n", build_info().c_str(), threads, device.c_str());
    if (on_device)
      std::printf("# device: triad %.2f GB/s (STREAM count, the bound); no flop peak measured\n", stream * 1e-9);
    else
      std::printf("# machine: triad %.2f GB/s (STREAM count), %.2f GB/s of traffic with write-allocate (the bound);\n"
                  "#          FMA peak %.2f GFLOP/s double, %.2f single; machine balance %.1f flop/byte (double)\n",
                  stream * 1e-9, bw * 1e-9, peak * 1e-9, peak_single * 1e-9, peak / bw);

    const Problem P = make_problem(spec);
    const GridDims& g = P.grid;
    const tresca::index N = g.nodes(), n = 3 * N, M = g.nx() * g.ny();
    // the triad over three vectors of this level: well above the memory
    // triad where they fit in the caches, and then so do the kernels' fields
    const double level_triad = triad_bandwidth(n, int(std::min(reps, 10LL))) * bw / stream;
    const bool cache_resident = level_triad > 1.25 * bw;
    const ElasticityStencil k = build_elasticity_stencil(g, P.interior_faces, P.spec.E, P.spec.nu);
    std::vector<real> hx(n), hb(n);
    for (tresca::index i = 0; i < n; ++i) {
      hx[i] = real((i * 7919) % 1000) * 1e-3;
      hb[i] = real((i * 104729) % 1000) * 1e-3;
    }
    Field<real> x = placed_field<real>(hx), b = placed_field<real>(hb), y(n), z(n), w(n), B(4 * M, 1.0);
    GridDims c = g;
    c.ex = (c.ex + 1) / 2;
    c.ey = (c.ey + 1) / 2;
    c.ez = (c.ez + 1) / 2;
    const Transfer t = build_transfer(g, c);
    Field<real> xc(3 * c.nodes(), 0.5);
    Multigrid mg(g, P.interior_faces, P.spec.E, P.spec.nu);
    // the approximation step on as many nodes as the grid has (a streaming
    // size; the benchmark's own contact face is small enough to sit in cache)
    Field<real> lam(N, 1.0), phi(N, 1.0), gap(N), scale(N, 2e8),
                v(4 * N), w4(4 * N), d(3 * N);
    Field<std::uint8_t> status(N);

    const int R = int(reps);
    const double nodes = double(N), dofs = double(n);
    std::vector<Row> rows;
    auto add = [&](const char* name, double items, Cost cost, const std::function<void()>& f, bool single = false) {
      rows.push_back({name, items, best_of(R, f), cost, single});
    };
    add("apply y = Kx", dofs, nodes * kApplyCost, [&] { elasticity_apply(k, x.data(), y.data(), 0, g.nz()); });
    const ElasticityStencilT<float> kf = stencil_in_precision<float>(k);
    Field<float> xf = placed_field<float>(hx), yf(n);
    add("apply (float)", dofs, nodes * in_precision<float>(kApplyCost),
        [&] { elasticity_apply<float>(kf, xf.data(), yf.data(), 0, g.nz()); }, true);
    add("residual b - Kx", dofs, nodes * kResidualCost,
        [&] { elasticity_apply(k, x.data(), y.data(), 0, g.nz(), b.data()); });
    add("bottom block", 3.0 * M, double(M) * kBottomBlockCost,
        [&] { bottom_block_apply(g, B.data(), x.data(), operator_out(y.data())); });
    add("restriction", dofs, dofs * kRestrictCost, [&] { restrict_to_coarse(t, 3, x.data(), xc.data()); });
    add("prolongation (+=)", dofs, dofs * kProlongateCost, [&] { prolongate(t, 3, xc.data(), y.data(), y.data()); });
    // the V-cycle's transfers are in its precision (float by default)
    Field<float> xcf(3 * c.nodes(), 0.5f), ypf(n, 0.0f);
    add("restriction (float)", dofs, dofs * in_precision<float>(kRestrictCost),
        [&] { restrict_to_coarse<float>(t, 3, xf.data(), xcf.data()); }, true);
    add("prolongation (float)", dofs, dofs * in_precision<float>(kProlongateCost),
        [&] { prolongate<float>(t, 3, xcf.data(), ypf.data(), ypf.data()); }, true);
    real sink = 0;
    add("dot", dofs, dofs * kDotCost, [&] { sink += 1e-300 * dot(n, x.data(), b.data()); });
    add("axpy", dofs, dofs * kAxpyCost, [&] { axpy(n, 1e-9, x.data(), y.data()); });
    add("cg_update", dofs, dofs * kCgUpdateCost, [&] { cg_update(n, 1e-9, x.data(), b.data(), z.data(), w.data()); });
    add("cheb_update", dofs, dofs * kChebUpdateCost,
        [&] { cheb_update(n, 0.5, 1e-9, b.data(), w.data(), x.data(), z.data()); });
    // the smoother's step as the V-cycle runs it: fused into the apply
    // (kernels/apply_out.hpp), in the V-cycle's float (dinv: b's values)
    Field<float> bf = placed_field<float>(hb), zf(n, 0.0f);
    add("Chebyshev step (float)", dofs, nodes * in_precision<float>(kChebStepCost), [&] {
      elasticity_apply<float>(kf, xf.data(), chebyshev_out<float>(bf.data(), bf.data(), 0.5f, 1e-9f, zf.data()),
                              RowBlock{0, g.nz(), 0, g.ny()});
    }, true);
    add("approximation step", nodes, nodes * kApproximationStepCost, [&] {
      approximation_step(N, ContactLaw{phi.data(), gap.data()}, scale.data(), scale.data(), x.data(), lam.data(), b.data(), v.data(), w4.data(), d.data(), status.data());
    });
    add("V-cycle (single)", dofs, Cost{}, [&] { mg.apply(b.data(), y.data()); });
    MGOptions md;
    md.precision = Precision::double_precision;
    Multigrid mgd(g, P.interior_faces, P.spec.E, P.spec.nu, md);
    add("V-cycle (double)", dofs, Cost{}, [&] { mgd.apply(b.data(), y.data()); });

    std::printf("# level %lld: mesh %s, %lld dofs, %.1f MB a vector\n", level, dims_string(spec).c_str(), (long long)n,
                8e-6 * double(n));
    if (cache_resident)
      std::printf("# note: this level's fields fit in the caches: the triad over three of its vectors runs at %.1f GB/s,\n"
                  "#       %.1fx the memory triad, so \"of BW\" above 100 %% is cache bandwidth; take a level whose\n"
                  "#       vectors exceed the caches (e.g. --level %lld) for memory-bound figures\n",
                  level_triad * 1e-9, level_triad / bw, level + 2);
    std::printf("%-20s %10s %11s %8s %8s %9s %8s %9s\n", "kernel", "time [ms]", "M items/s", "GB/s", "of BW",
                "GFLOP/s", "of peak", "of bound");
    Json kernels = Json::array();
    for (size_t i = 0; i < rows.size(); ++i) {
      const Row& r = rows[i];
      const double gbs = r.cost.bytes / r.seconds, gfs = r.cost.flops / r.seconds;
      const double pk = r.single ? peak_single : peak;
      const double bound = std::max(r.cost.bytes / bw, r.cost.flops / pk);
      char of_peak[16] = "-";
      if (!on_device) std::snprintf(of_peak, sizeof of_peak, "%.0f%%", 100 * gfs / pk);
      if (r.cost.bytes > 0)
        std::printf("%-20s %10.3f %11.1f %8.2f %7.0f%% %9.2f %8s %8.0f%%\n", r.name.c_str(), r.seconds * 1e3,
                    r.items / r.seconds * 1e-6, gbs * 1e-9, 100 * gbs / bw, gfs * 1e-9, of_peak,
                    100 * bound / r.seconds);
      else
        std::printf("%-20s %10.3f %11.1f %8s %8s %9s %8s %9s\n", r.name.c_str(), r.seconds * 1e3,
                    r.items / r.seconds * 1e-6, "-", "-", "-", "-", "-");
      kernels.push_back({{"kernel", r.name},
                         {"seconds", r.seconds},
                         {"items_per_s", r.items / r.seconds},
                         {"bytes_per_s", gbs},
                         {"flops_per_s", gfs},
                         {"fraction_of_bandwidth", gbs / bw},
                         {"fraction_of_peak", on_device ? Json(nullptr) : Json(gfs / pk)},
                         {"fraction_of_bound", bound / r.seconds}});
    }
    if (sink != sink) std::printf("# (dot: not finite)\n");
    const Json out = {{"build", build_info()},
                      {"threads", threads},
                      {"device", device},
                      {"level", level},
                      {"triad_stream_bytes_per_s", stream},
                      {"bandwidth_bytes_per_s", bw},
                      {"level_triad_bytes_per_s", level_triad},
                      {"cache_resident", cache_resident},
                      {"peak_flops_per_s", on_device ? Json(nullptr) : Json(peak)},
                      {"peak_flops_per_s_single", on_device ? Json(nullptr) : Json(peak_single)},
                      {"kernels", kernels}};
    if (!json.empty()) write_file_atomic(json, json_text(out));
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "roofline: error: %s\n", e.what());
    return 2;
  }
}
