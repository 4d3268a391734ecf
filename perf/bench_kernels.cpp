// Kernel benchmarks (Google Benchmark). Rates use the cost models stated in
// the kernel headers (kApplyCost etc.; per dof = per node / 3). The build's ISA
// and vector width are printed in the context header.
//   OMP_NUM_THREADS=2 build/bin/bench_kernels --benchmark_filter=Apply
#include <benchmark/benchmark.h>
#include <omp.h>

#include <cstdio>
#include <cstring>
#include <vector>

#include "core/io/cli.hpp"

#include "core/multigrid/multigrid.hpp"
#include "core/fem/problem.hpp"
#include "kernels/launch.hpp"
#include "kernels/isa.hpp"
#include "kernels/transfer.hpp"
#include "kernels/vector_ops.hpp"

namespace tresca {
namespace {

std::vector<real> ramp(index n) {
  std::vector<real> v(n);
  for (index i = 0; i < n; ++i) v[i] = real((i * 7919) % 1000) * 1e-3;
  return v;
}

void set_rates(benchmark::State& st, double dofs, double bytes_per_dof, double flops_per_dof) {
  const double it = double(st.iterations());
  st.counters["DoF/s"] = benchmark::Counter(dofs * it, benchmark::Counter::kIsRate);
  st.counters["bytes/s"] = benchmark::Counter(dofs * bytes_per_dof * it, benchmark::Counter::kIsRate);
  st.counters["FLOP/s"] = benchmark::Counter(dofs * flops_per_dof * it, benchmark::Counter::kIsRate);
  // (not "threads": Google Benchmark's own key of every run, the benchmark's threads)
  st.counters["omp_threads"] = omp_get_max_threads();
  st.counters["dofs"] = dofs;
}

// Where a benchmark runs: the host's kernels, the serial _ref twin, or the
// device backend (kernels/launch.hpp: a TRESCA_OFFLOAD build; every Field
// made in the benchmark then lives in device memory, and the timed loop is
// the kernels alone, no copies; on the host where there is no GPU: the
// context header's "device" says which).
enum class Run { host, ref, device };

// launches on the device for a Run::device benchmark's life; false (and the
// benchmark skipped with the reason) where the build has no device backend
bool run_where(benchmark::State& st, Run run) {
  if (run != Run::device) return true;
  if (!offload_built()) {
    st.SkipWithError("built without TRESCA_OFFLOAD (no device backend)");
    return false;
  }
  set_launch_on_device(true);
  return true;
}
void done(Run run) {
  if (run == Run::device) set_launch_on_device(false);
}

// T: double, float (the single-precision V-cycle's apply); Run::ref: the serial _ref twin (double)
template <class T, Run kRun>
void BM_Apply(benchmark::State& st) {
  const Problem P = make_problem(spec_for_level(int(st.range(0))));
  if (!run_where(st, kRun)) return;
  {
    const ElasticityStencil k = build_elasticity_stencil(P.grid, P.interior_faces, P.spec.E, P.spec.nu);
    const ElasticityStencilT<T> kt = stencil_in_precision<T>(k);
    Field<T> x = placed_field<T>(ramp(k.size())), y(k.size());
    for (auto _ : st) {
      if constexpr (kRun == Run::ref)
        elasticity_apply_ref(k, x.data(), y.data(), 0, P.grid.nz());
      else
        elasticity_apply<T>(kt, x.data(), y.data(), 0, P.grid.nz());
      benchmark::DoNotOptimize(y.data());
      benchmark::ClobberMemory();
    }
  }
  done(kRun);
  const Cost c = in_precision<T>(kApplyCost);
  set_rates(st, double(P.dofs()), c.bytes / 3, c.flops / 3);
}
BENCHMARK_TEMPLATE(BM_Apply, double, Run::host)->Name("Apply")->DenseRange(6, 12, 2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_Apply, float, Run::host)->Name("ApplyFloat")->DenseRange(6, 12, 2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_Apply, double, Run::ref)->Name("ApplyRef")->DenseRange(6, 10, 2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_Apply, double, Run::device)->Name("DeviceApply")->DenseRange(8, 13)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_Apply, float, Run::device)->Name("DeviceApplyFloat")->DenseRange(8, 13)->UseRealTime()->Unit(benchmark::kMillisecond);
// The apply on a brick of ex x ey x ez elements (double, the x = 0 face
// clamped), by the shape of its fields: long rows that stay in cache
// (1008x4x4), short ones (64x4x4), and a level-12-sized brick that does not
// fit the caches (256x128x128): what a node costs in cache, what a row's
// ends add, and what the memory adds can be read apart. ns/node: the time
// a node (perf/RESULTS.md §0zj).
void BM_ApplyShape(benchmark::State& st) {
  GridDims g;
  g.ex = st.range(0);
  g.ey = st.range(1);
  g.ez = st.range(2);
  const ElasticityStencil k = build_elasticity_stencil(g, kFaceX0, 2e11, 0.3);
  Field<real> x = placed_field<real>(ramp(k.size())), y(k.size());
  for (auto _ : st) {
    elasticity_apply<real>(k, x.data(), y.data(), 0, g.nz());
    benchmark::DoNotOptimize(y.data());
    benchmark::ClobberMemory();
  }
  st.counters["ns/node"] = benchmark::Counter(double(g.nodes()) * double(st.iterations()),
                                              benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  set_rates(st, double(k.size()), kApplyCost.bytes / 3, kApplyCost.flops / 3);
}
BENCHMARK(BM_ApplyShape)->Name("ApplyShape")->Args({1008, 4, 4})->Args({64, 4, 4})->Args({256, 128, 128})->UseRealTime()->Unit(benchmark::kMillisecond);

// One Chebyshev step of the smoother on a level's vectors, in the V-cycle's
// float: fused into the apply (kernels/apply_out.hpp: the sweep writes the
// new iterate over the one before) against the residual and the update it
// replaced (two sweeps, r written and read back). Bytes: the fused model,
// kChebStepCost, for both, so their GB/s compare as times do.
template <bool kFused>
void BM_ChebStep(benchmark::State& st) {
  using T = float;
  const Problem P = make_problem(spec_for_level(int(st.range(0))));
  const ElasticityStencil k = build_elasticity_stencil(P.grid, P.interior_faces, P.spec.E, P.spec.nu);
  const ElasticityStencilT<T> kt = stencil_in_precision<T>(k);
  const index n = k.size();
  Field<T> x = placed_field<T>(ramp(n)), y(n), b = placed_field<T>(ramp(n)), r(n), dinv(n);
  fill<T>(n, T(1e-3), dinv.data());
  const RowBlock all{0, P.grid.nz(), 0, P.grid.ny()};
  for (auto _ : st) {
    if constexpr (kFused) {
      elasticity_apply<T>(kt, x.data(), chebyshev_out<T>(b.data(), dinv.data(), 0.5f, 0.25f, y.data()), all);
    } else {
      elasticity_apply<T>(kt, x.data(), r.data(), all, b.data());
      cheb_update<T>(n, 0.5f, 0.25f, dinv.data(), r.data(), x.data(), y.data());
    }
    benchmark::DoNotOptimize(y.data());
    benchmark::ClobberMemory();
  }
  const Cost c = in_precision<T>(kChebStepCost);
  set_rates(st, double(P.dofs()), c.bytes / 3, c.flops / 3);
}
BENCHMARK_TEMPLATE(BM_ChebStep, true)->Name("ChebStepFused")->DenseRange(8, 12, 2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_ChebStep, false)->Name("ChebStepUnfused")->DenseRange(8, 12, 2)->UseRealTime()->Unit(benchmark::kMillisecond);

template <Run kRun>
void BM_VCycle(benchmark::State& st) {
  const Problem P = make_problem(spec_for_level(int(st.range(0))));
  auto h = ramp(P.dofs());
  zero_constrained(P.grid, P.interior_faces, h.data());
  if (!run_where(st, kRun)) return;
  {
    Multigrid mg(P.grid, P.interior_faces, P.spec.E, P.spec.nu);
    Field<real> r = placed_field<real>(h), z(P.dofs());
    const LaunchCounts n0 = launch_counts();
    for (auto _ : st) {
      mg.apply(r.data(), z.data());
      benchmark::DoNotOptimize(z.data());
    }
    // the fork/join census of one V-cycle (launch.hpp)
    const LaunchCounts n1 = launch_counts();
    const double cycles = double(st.iterations());
    st.counters["regions"] = double(n1.threaded - n0.threaded) / cycles;
    st.counters["one_thread"] = double(n1.one_thread - n0.one_thread) / cycles;
    st.counters["device_launches"] = double(n1.device - n0.device) / cycles;
  }
  done(kRun);
  set_rates(st, double(P.dofs()), 0, 0);
}
BENCHMARK_TEMPLATE(BM_VCycle, Run::host)->Name("VCycle")->DenseRange(6, 10, 2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_VCycle, Run::device)->Name("DeviceVCycle")->DenseRange(8, 13)->UseRealTime()->Unit(benchmark::kMillisecond);

// One empty parallel region through the launch layer: the price of a fork,
// a join and its barrier at this thread count (times the `regions` of a
// V-cycle or the census of `tresca --profile`: what the threads cost).
void BM_ParallelRegion(benchmark::State& st) {
  for (auto _ : st) for_each_host_share("empty region", omp_get_max_threads(), Cost{kParallelWork, 0}, [](Share) {});
  st.counters["omp_threads"] = omp_get_max_threads();
}
BENCHMARK(BM_ParallelRegion)->Name("ParallelRegion")->UseRealTime();

template <Run kRun>
void BM_Transfer(benchmark::State& st) {
  const Problem P = make_problem(spec_for_level(int(st.range(0))));
  GridDims c = P.grid;
  c.ex = (c.ex + 1) / 2;
  c.ey = (c.ey + 1) / 2;
  c.ez = (c.ez + 1) / 2;
  if (!run_where(st, kRun)) return;
  {
    const Transfer t = build_transfer(P.grid, c);
    Field<real> f = placed_field<real>(ramp(3 * P.grid.nodes())), cc(3 * c.nodes());
    for (auto _ : st) {
      restrict_to_coarse(t, 3, f.data(), cc.data());
      prolongate(t, 3, cc.data(), f.data());
      benchmark::DoNotOptimize(f.data());
    }
  }
  done(kRun);
  const Cost cost = kRestrictCost + kProlongateCost;
  set_rates(st, double(3 * P.grid.nodes()), cost.bytes, cost.flops);
}
BENCHMARK_TEMPLATE(BM_Transfer, Run::host)->Name("RestrictProlong")->DenseRange(6, 10, 2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_Transfer, Run::device)->Name("DeviceRestrictProlong")->DenseRange(8, 13)->UseRealTime()->Unit(benchmark::kMillisecond);

// the vector kernels: 0 dot, 1 axpy, 2 cg_update
template <int kKernel, Run kRun>
void BM_Vector(benchmark::State& st) {
  const index n = index(st.range(0));
  const std::vector<real> h = ramp(n);
  if (!run_where(st, kRun)) return;
  {
    Field<real> v[4] = {placed_field<real>(h), placed_field<real>(h), placed_field<real>(h), placed_field<real>(h)};
    for (auto _ : st) {
      if (kKernel == 0) benchmark::DoNotOptimize(dot(n, v[0].data(), v[1].data()));
      if (kKernel == 1) axpy(n, 1e-9, v[0].data(), v[1].data());
      if (kKernel == 2) benchmark::DoNotOptimize(cg_update(n, 1e-9, v[0].data(), v[1].data(), v[2].data(), v[3].data()));
    }
  }
  done(kRun);
  const Cost c = kKernel == 0 ? kDotCost : kKernel == 1 ? kAxpyCost : kCgUpdateCost;
  set_rates(st, double(n), c.bytes, c.flops);
}
BENCHMARK_TEMPLATE(BM_Vector, 0, Run::host)->Name("Dot")->Arg(1 << 20)->Arg(1 << 24)->UseRealTime();
// (1024 entries: the time of a launch itself, a target region's fixed cost, which
// a solve pays at each of its thousands of launches: --profile's "on the device")
BENCHMARK_TEMPLATE(BM_Vector, 0, Run::device)->Name("DeviceDot")->Arg(1 << 10)->Arg(1 << 24)->Arg(1 << 27)->UseRealTime();
BENCHMARK_TEMPLATE(BM_Vector, 1, Run::device)->Name("DeviceAxpy")->Arg(1 << 10)->Arg(1 << 24)->Arg(1 << 27)->UseRealTime();
BENCHMARK_TEMPLATE(BM_Vector, 2, Run::device)->Name("DeviceCgUpdate")->Arg(1 << 24)->Arg(1 << 27)->UseRealTime();

}  // namespace
}  // namespace tresca

static const char* kHelp =
    "usage: bench_kernels [Google Benchmark options]\n"
    "The kernels one by one on the fields of mesh levels 6-12 (Apply, ApplyFloat, ApplyRef: the\n"
    "serial _ref twin, ApplyShape: the apply by the shape of its brick, with ns/node, VCycle,\n"
    "RestrictProlong, Dot), each with the counters DoF/s, bytes/s and\n"
    "FLOP/s from the kernels' cost models, omp_threads and dofs; the build (ISA, vector width,\n"
    "compiler) and the offload device are in the context header. VCycle also counts its\n"
    "launches (regions: parallel regions a cycle, one_thread: launches too small for threads);\n"
    "ParallelRegion: the time of one empty parallel region (fork, join, barrier) at this\n"
    "thread count. Device*: the same kernels\n"
    "(DeviceApply, DeviceApplyFloat, DeviceVCycle, DeviceRestrictProlong, DeviceDot, DeviceAxpy,\n"
    "DeviceCgUpdate) with every field in device memory, through the offload backend (a\n"
    "-DTRESCA_OFFLOAD=ON build; otherwise they are skipped with that message).\n"
    "  --benchmark_filter=REGEX        which ones, e.g. 'Apply/10|VCycle/10'\n"
    "  --benchmark_repetitions=N       repeat each; with --benchmark_report_aggregates_only=true\n"
    "                                  only the mean, median, stddev and cv are printed\n"
    "  --benchmark_format=json, --benchmark_out=FILE  machine-readable output\n"
    "  --benchmark_list_tests          the names\n"
    "  --help-benchmark                Google Benchmark's own list of options\n"
    "  -h, --help                      this text;  --version  the version and the build\n"
    "Threads: OMP_NUM_THREADS (default all cores).\n";

int main(int argc, char** argv) {
  static char benchmark_help[] = "--help";  // Google Benchmark's own --help
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "-h") || !std::strcmp(argv[i], "--help")) {
      std::fputs(kHelp, stdout);
      return 0;
    }
    if (!std::strcmp(argv[i], "--version")) {
      std::fputs(tresca::version_text("bench_kernels").c_str(), stdout);
      return 0;
    }
    if (!std::strcmp(argv[i], "--help-benchmark")) argv[i] = benchmark_help;
  }
  benchmark::AddCustomContext("tresca kernels", tresca::build_info());
  benchmark::AddCustomContext("device", tresca::device_description());
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
