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
#include "kernels/simd.hpp"
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

// T: double, float (the single-precision V-cycle's apply); kRef: the serial _ref twin (double)
template <class T, bool kRef>
void BM_Apply(benchmark::State& st) {
  const Problem P = make_problem(spec_for_level(int(st.range(0))));
  const ElasticityStencil k = build_elasticity_stencil(P.grid, P.interior_faces, P.spec.E, P.spec.nu);
  const ElasticityStencilT<T> kt = stencil_in_precision<T>(k);
  const auto xd = ramp(k.size());
  std::vector<T> x(xd.begin(), xd.end()), y(k.size());
  for (auto _ : st) {
    if constexpr (kRef)
      elasticity_apply_ref(k, x.data(), y.data(), 0, P.grid.nz());
    else
      elasticity_apply<T>(kt, x.data(), y.data(), 0, P.grid.nz());
    benchmark::DoNotOptimize(y.data());
    benchmark::ClobberMemory();
  }
  const Cost c = in_precision<T>(kApplyCost);
  set_rates(st, double(k.size()), c.bytes / 3, c.flops / 3);
}
BENCHMARK_TEMPLATE(BM_Apply, double, false)->Name("Apply")->DenseRange(6, 12, 2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_Apply, float, false)->Name("ApplyFloat")->DenseRange(6, 12, 2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_Apply, double, true)->Name("ApplyRef")->DenseRange(6, 10, 2)->UseRealTime()->Unit(benchmark::kMillisecond);

void BM_VCycle(benchmark::State& st) {
  const Problem P = make_problem(spec_for_level(int(st.range(0))));
  Multigrid mg(P.grid, P.interior_faces, P.spec.E, P.spec.nu);
  auto r = ramp(P.dofs());
  zero_constrained(P.grid, P.interior_faces, r.data());
  std::vector<real> z(P.dofs());
  for (auto _ : st) {
    mg.apply(r.data(), z.data());
    benchmark::DoNotOptimize(z.data());
  }
  set_rates(st, double(P.dofs()), 0, 0);
}
BENCHMARK(BM_VCycle)->Name("VCycle")->DenseRange(6, 10, 2)->UseRealTime()->Unit(benchmark::kMillisecond);

void BM_Transfer(benchmark::State& st) {
  const Problem P = make_problem(spec_for_level(int(st.range(0))));
  GridDims c = P.grid;
  c.ex = (c.ex + 1) / 2;
  c.ey = (c.ey + 1) / 2;
  c.ez = (c.ez + 1) / 2;
  const Transfer t = build_transfer(P.grid, c);
  auto f = ramp(3 * P.grid.nodes());
  std::vector<real> cc(3 * c.nodes());
  for (auto _ : st) {
    restrict_to_coarse(t, 3, f.data(), cc.data());
    prolongate(t, 3, cc.data(), f.data());
    benchmark::DoNotOptimize(f.data());
  }
  const Cost cost = kRestrictCost + kProlongateCost;
  set_rates(st, double(3 * P.grid.nodes()), cost.bytes, cost.flops);
}
BENCHMARK(BM_Transfer)->Name("RestrictProlong")->DenseRange(6, 10, 2)->UseRealTime()->Unit(benchmark::kMillisecond);

void BM_Dot(benchmark::State& st) {
  const index n = index(st.range(0));
  auto x = ramp(n), y = ramp(n);
  for (auto _ : st) benchmark::DoNotOptimize(dot(n, x.data(), y.data()));
  set_rates(st, double(n), kDotCost.bytes, kDotCost.flops);
}
BENCHMARK(BM_Dot)->Name("Dot")->Arg(1 << 20)->Arg(1 << 24)->UseRealTime();

// The same vector kernels through the device backend (kernels/launch.hpp):
// their vectors in device memory, launched as target regions (a
// TRESCA_OFFLOAD build; on the host where there is no GPU, "device" in the
// context header says which). The timed loop is the kernel alone: no copies.
template <int kKernel>  // 0: dot, 1: axpy, 2: cg_update
void BM_Device(benchmark::State& st) {
  if (!offload_built()) {
    st.SkipWithError("built without TRESCA_OFFLOAD (no device backend)");
    return;
  }
  const index n = index(st.range(0));
  const std::vector<real> h = ramp(n);
  const std::size_t bytes = std::size_t(n) * sizeof(real);
  real* v[4];
  for (real*& p : v) {
    p = static_cast<real*>(device_allocate(bytes));
    copy_to_device(p, h.data(), bytes);
  }
  set_launch_on_device(true);
  for (auto _ : st) {
    if (kKernel == 0) benchmark::DoNotOptimize(dot(n, v[0], v[1]));
    if (kKernel == 1) axpy(n, 1e-9, v[0], v[1]);
    if (kKernel == 2) benchmark::DoNotOptimize(cg_update(n, 1e-9, v[0], v[1], v[2], v[3]));
  }
  set_launch_on_device(false);
  for (real* p : v) device_free(p);
  const Cost c = kKernel == 0 ? kDotCost : kKernel == 1 ? kAxpyCost : kCgUpdateCost;
  set_rates(st, double(n), c.bytes, c.flops);
}
// The stencil apply on the device (its row form, elasticity_apply_rows),
// stencil and vectors in device memory; T = double, float
template <class T>
void BM_DeviceApply(benchmark::State& st) {
  if (!offload_built()) {
    st.SkipWithError("built without TRESCA_OFFLOAD (no device backend)");
    return;
  }
  const Problem P = make_problem(spec_for_level(int(st.range(0))));
  const ElasticityStencil k64 = build_elasticity_stencil(P.grid, P.interior_faces, P.spec.E, P.spec.nu);
  const ElasticityStencilT<T> k = stencil_in_precision<T>(k64);
  const index n = k.size();
  const std::vector<real> h = ramp(n);
  const std::vector<T> ht(h.begin(), h.end());
  const DeviceStencil<T> dk(k);
  T* x = static_cast<T*>(device_allocate(n * sizeof(T)));
  T* y = static_cast<T*>(device_allocate(n * sizeof(T)));
  copy_to_device(x, ht.data(), n * sizeof(T));
  const RowBlock all{0, P.grid.nz(), 0, P.grid.ny()};
  set_launch_on_device(true);
  for (auto _ : st) elasticity_apply_rows(dk.view(), x, y, all);
  set_launch_on_device(false);
  device_free(x);
  device_free(y);
  set_rates(st, double(n), in_precision<T>(kApplyCost).bytes / 3, kApplyCost.flops / 3);
}
BENCHMARK_TEMPLATE(BM_DeviceApply, double)->Name("DeviceApply")->DenseRange(8, 13)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_DeviceApply, float)->Name("DeviceApplyFloat")->DenseRange(8, 13)->UseRealTime()->Unit(benchmark::kMillisecond);

BENCHMARK_TEMPLATE(BM_Device, 0)->Name("DeviceDot")->Arg(1 << 24)->Arg(1 << 27)->UseRealTime();
BENCHMARK_TEMPLATE(BM_Device, 1)->Name("DeviceAxpy")->Arg(1 << 24)->Arg(1 << 27)->UseRealTime();
BENCHMARK_TEMPLATE(BM_Device, 2)->Name("DeviceCgUpdate")->Arg(1 << 24)->Arg(1 << 27)->UseRealTime();

}  // namespace
}  // namespace tresca

static const char* kHelp =
    "usage: bench_kernels [Google Benchmark options]\n"
    "The kernels one by one on the fields of mesh levels 6-12 (Apply, ApplyFloat, ApplyRef: the\n"
    "serial _ref twin, VCycle, RestrictProlong, Dot), each with the counters DoF/s, bytes/s and\n"
    "FLOP/s from the kernels' cost models, omp_threads and dofs; the build (ISA, vector width,\n"
    "compiler) and the offload device are in the context header. DeviceDot, DeviceAxpy and\n"
    "DeviceCgUpdate: the vector kernels in device memory through the offload backend\n"
    "(a -DTRESCA_OFFLOAD=ON build; otherwise they are skipped with that message).\n"
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
