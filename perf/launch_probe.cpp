// What each form of an OpenMP target region costs with this compiler's
// libgomp, apart from any kernel of ours: the launch floor (an empty
// region), and an axpy y += a x over n entries (n = 1024: the launch;
// n large: the bandwidth) under the constructs kernels/launch.hpp could use.
// On an H200 (RESULTS.md §0zm) a teams region that names its thread_limit
// cost about 4 us a team, serialised; this measures the same teams without
// the clause, and the other forms, in one short run (`run.sh launch`).
//
//   launch_probe [N]      N: the large size (default 2^27 doubles a vector)
//
// Like the launchers, a region maps nothing: its operands travel in a
// `declare target` variable (kernels/launch.hpp, detail::send_to_device).
// Medians of repeated launches (200 at 1024 entries, 10 at N; a tenth of
// that without a GPU), each timed from the update of its operands to the
// region's end.
#include <omp.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "kernels/launch.hpp"

namespace {
struct Operands {
  double* x;
  double* y;
  long n;
  double a;
};
}  // namespace
#pragma omp declare target
static Operands probe_args;
#pragma omp end declare target

namespace {
void send(double* x, double* y, long n, double a) {
  probe_args = {x, y, n, a};
#pragma omp target update to(probe_args)
}

// each form as a function of its own: one target region each
#define TRESCA_PROBE_AXPY(name, construct)                                                        \
  void name() {                                                                                   \
    _Pragma(construct) for (long i = 0; i < probe_args.n; ++i) probe_args.y[i] += probe_args.a * probe_args.x[i]; \
  }
TRESCA_PROBE_AXPY(axpy_teams, "omp target teams distribute parallel for simd")
TRESCA_PROBE_AXPY(axpy_teams_limit8, "omp target teams distribute parallel for simd thread_limit(8)")
TRESCA_PROBE_AXPY(axpy_teams_no_parallel, "omp target teams distribute simd")
TRESCA_PROBE_AXPY(axpy_teams_256, "omp target teams distribute parallel for simd num_teams(256)")
TRESCA_PROBE_AXPY(axpy_teams_limit32_132, "omp target teams distribute parallel for simd num_teams(132) thread_limit(32)")
TRESCA_PROBE_AXPY(axpy_one_team, "omp target parallel for simd")
#undef TRESCA_PROBE_AXPY

void empty_target() {
#pragma omp target
  {
    if (probe_args.n < 0) probe_args.n = 0;
  }
}
void empty_teams() {
#pragma omp target teams
  {
    if (probe_args.n < 0) probe_args.n = 0;
  }
}
void empty_teams_limit8() {
#pragma omp target teams thread_limit(8)
  {
    if (probe_args.n < 0) probe_args.n = 0;
  }
}

struct Form {
  const char* name;
  void (*run)();
  bool empty;  // (run once, at the small size)
};
}  // namespace

int main(int argc, char** argv) {
  const long large = argc > 1 ? std::atol(argv[1]) : (1L << 27);
  if (large < 1024) {
    std::fprintf(stderr, "launch_probe: N must be at least 1024\n");
    return 2;
  }
  const int dev = omp_get_default_device();
  const bool gpu = omp_get_num_devices() > 0;
  std::printf("# launch_probe: %s; %d device(s); vectors of 1024 and %ld doubles\n",
              tresca::device_description().c_str(), omp_get_num_devices(), large);
  double* x = static_cast<double*>(omp_target_alloc(std::size_t(large) * sizeof(double), dev));
  double* y = static_cast<double*>(omp_target_alloc(std::size_t(large) * sizeof(double), dev));
  if (!x || !y) {
    std::fprintf(stderr, "launch_probe: cannot allocate 2 x %ld doubles on the device\n", large);
    return 4;
  }
  const Form forms[] = {
      {"target (one team), empty", empty_target, true},
      {"target teams, empty", empty_teams, true},
      {"target teams thread_limit(8), empty", empty_teams_limit8, true},
      {"teams distribute parallel for simd", axpy_teams, false},
      {"... thread_limit(8)", axpy_teams_limit8, false},
      {"teams distribute simd (no parallel)", axpy_teams_no_parallel, false},
      {"... parallel for simd num_teams(256)", axpy_teams_256, false},
      {"... num_teams(132) thread_limit(32)", axpy_teams_limit32_132, false},
      {"target parallel for simd (one team)", axpy_one_team, false},
  };
  std::printf("%-40s %12s %12s %12s %10s\n", "form", "n", "median [us]", "min [us]", "GB/s");
  for (const long n : {1024L, large}) {
    send(x, y, n, 0.0);
    axpy_teams();  // (first touch)
    for (const Form& f : forms) {
      if (f.empty && n != 1024) continue;
      send(x, y, n, 0.5);
      f.run();  // (the first launch of a region loads it)
      const int reps = (n <= 4096 ? 200 : 10) / (gpu ? 1 : 10);  // (without a GPU: the code path, briefly)
      std::vector<double> t;
      for (int r = 0; r < reps; ++r) {
        const double t0 = omp_get_wtime();
        send(x, y, n, 0.5);
        f.run();
        t.push_back(omp_get_wtime() - t0);
      }
      std::sort(t.begin(), t.end());
      const double median = t[t.size() / 2];
      std::printf("%-40s %12ld %12.1f %12.1f %10.1f\n", f.name, n, median * 1e6, t[0] * 1e6,
                  f.empty ? 0.0 : 24.0 * double(n) / median * 1e-9);
    }
  }
  omp_target_free(x, dev);
  omp_target_free(y, dev);
  return 0;
}
