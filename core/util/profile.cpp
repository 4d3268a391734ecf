#include "core/util/profile.hpp"

#include <omp.h>
#include <sys/resource.h>

#include <cstdio>

namespace tresca {

namespace {
ProfileEntry g_entries[int(Kernel::count)];
}

const char* kernel_name(Kernel k) {
  static const char* names[] = {"apply (K x)", "apply (bottom block)", "diagonal", "smoother (Chebyshev)",
                                "prolongation", "restriction", "coarse solve", "vector updates",
                                "contact maps", "inner CG (total)", "outer CG (total)"};
  return names[int(k)];
}

double wall_time() { return omp_get_wtime(); }

double peak_memory_bytes() {
  struct rusage ru;
  getrusage(RUSAGE_SELF, &ru);
  return double(ru.ru_maxrss) * 1024.0;  // Linux reports kilobytes
}

void profile_add(Kernel k, double seconds, double bytes, double flops) {
  // called from the serial driver thread only (kernels parallelise inside)
  ProfileEntry& e = g_entries[int(k)];
  e.calls += 1;
  e.seconds += seconds;
  e.bytes += bytes;
  e.flops += flops;
}

std::string profile_table(double total) {
  std::string out;
  char line[256];
  std::snprintf(line, sizeof line, "%-22s %10s %10s %7s %9s %9s\n", "kernel", "calls", "time [s]", "share",
                "GB/s", "GFLOP/s");
  out += line;
  for (int i = 0; i < int(Kernel::count); ++i) {
    const ProfileEntry& e = g_entries[i];
    if (e.calls == 0) continue;
    // rows that contain other rows, or have no traffic model, show no rates
    const bool nested = Kernel(i) == Kernel::inner_cg || Kernel(i) == Kernel::outer_cg ||
                        Kernel(i) == Kernel::smoother || Kernel(i) == Kernel::coarse_solve;
    char gbs[16] = "-", gflops[16] = "-";
    if (!nested && e.seconds > 0) {
      std::snprintf(gbs, sizeof gbs, "%.2f", e.bytes / e.seconds * 1e-9);
      std::snprintf(gflops, sizeof gflops, "%.2f", e.flops / e.seconds * 1e-9);
    }
    std::snprintf(line, sizeof line, "%-22s %10lld %10.3f %6.1f%% %9s %9s\n", kernel_name(Kernel(i)), e.calls,
                  e.seconds, total > 0 ? 100 * e.seconds / total : 0.0, gbs, gflops);
    out += line;
  }
  out += "(smoother, inner and outer CG rows contain the kernel rows; their shares overlap)\n";
  return out;
}

}  // namespace tresca
