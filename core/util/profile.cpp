#include "core/util/profile.hpp"

#include <omp.h>
#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "kernels/launch.hpp"
#include "kernels/vector_ops.hpp"

namespace tresca {

namespace {
ProfileEntry g_entries[int(Kernel::count)];
LaunchCounts g_launches_at_reset;  // the launch census when the profile was last reset
std::vector<KernelLaunches> g_kernels_at_reset;  // and the census by kernel
// the seconds in launches that ran in parallel: host parallel regions and target regions
double parallel_seconds(const LaunchCounts& c) { return c.threaded_seconds + c.device_seconds; }
double parallel_seconds_so_far() { return parallel_seconds(launch_counts()); }
}

const char* kernel_name(Kernel k) {
  static const char* names[] = {"apply (K x)", "apply (bottom block)", "diagonal", "smoother (Chebyshev)",
                                "prolongation", "restriction", "coarse solve", "vector updates",
                                "contact maps", "inner CG (total)", "outer CG (total)",
                                "host levels (total)"};
  return names[int(k)];
}

double wall_time() { return omp_get_wtime(); }

double triad_bandwidth(index n, int reps) {
  Field<real> a(n), b(n), c(n);  // (first touched here, by one thread: one NUMA node assumed)
  real *pa = a.data(), *pb = b.data(), *pc = c.data();
  fill(n, real(1), pb);
  fill(n, real(2), pc);
  auto run = [&] { triad(n, pb, 3, pc, pa); };
  run();  // warm-up
  const double t = best_time(reps, run);
  real mid = 0;  // (a may live on the device)
  space_copy(Space::host, &mid, a.space(), pa + n / 2, sizeof(real));
  if (mid != 7) throw std::runtime_error("triad_bandwidth: the triad computed a wrong value");
  return kTriadCost.bytes * double(n) / t;
}

double peak_memory_bytes() {
  struct rusage ru;
  getrusage(RUSAGE_SELF, &ru);
  return double(ru.ru_maxrss) * 1024.0;  // Linux reports kilobytes
}

namespace {
ScopedTimer* g_innermost = nullptr;
}

ScopedTimer::ScopedTimer(Kernel k, Cost cost)
    : k_(k), b_(cost.bytes), f_(cost.flops), t0_(wall_time()), parallel0_(parallel_seconds_so_far()),
      outer_(g_innermost) {
  g_innermost = this;
}

ScopedTimer::~ScopedTimer() {
  const double dt = wall_time() - t0_, parallel = parallel_seconds_so_far() - parallel0_;
  g_innermost = outer_;
  if (outer_) {
    outer_->nested_ += dt;
    outer_->nested_parallel_ += parallel;
  }
  // called from the serial driver thread only (kernels parallelise inside)
  ProfileEntry& e = g_entries[int(k_)];
  e.calls += 1;
  e.seconds += dt;
  e.self_seconds += dt - nested_;
  e.parallel_seconds += parallel;
  e.self_parallel_seconds += parallel - nested_parallel_;
  e.bytes += b_;
  e.flops += f_;
}

void profile_reset() {
  for (ProfileEntry& e : g_entries) e = ProfileEntry{};
  g_launches_at_reset = launch_counts();
  g_kernels_at_reset = launches_by_kernel();
}

std::vector<KernelLaunches> kernel_launches_since_reset() {
  std::vector<KernelLaunches> out;
  for (KernelLaunches k : launches_by_kernel()) {
    for (const KernelLaunches& r : g_kernels_at_reset)
      if (r.kernel == k.kernel && r.ran == k.ran) {
        k.calls -= r.calls;
        k.seconds -= r.seconds;
        k.bytes -= r.bytes;
        k.flops -= r.flops;
      }
    if (k.calls > 0) out.push_back(k);
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const KernelLaunches& a, const KernelLaunches& b) { return a.seconds > b.seconds; });
  return out;
}

LaunchCounts launches_since_reset() {
  const LaunchCounts& r = g_launches_at_reset;
  LaunchCounts d = launch_counts();
  d.threaded -= r.threaded;
  d.one_thread -= r.one_thread;
  d.device -= r.device;
  d.threaded_seconds -= r.threaded_seconds;
  d.one_thread_seconds -= r.one_thread_seconds;
  d.device_seconds -= r.device_seconds;
  for (int k = 0; k < LaunchCounts::kSizes; ++k) {
    d.by_size[k] -= r.by_size[k];
    d.by_size_seconds[k] -= r.by_size_seconds[k];
    d.by_size_work[k] -= r.by_size_work[k];
  }
  return d;
}

double one_thread_seconds(double total) { return std::max(0.0, total - parallel_seconds(launches_since_reset())); }

std::vector<ProfileRow> profile_rows(double total) {
  std::vector<ProfileRow> rows;
  double counted = 0, counted_parallel = 0;
  for (int i = 0; i < int(Kernel::count); ++i) {
    const ProfileEntry& e = g_entries[i];
    if (e.calls == 0) continue;
    ProfileRow r;
    r.kernel = kernel_name(Kernel(i));
    r.calls = e.calls;
    r.seconds = e.seconds;
    r.self_seconds = e.self_seconds;
    r.share = total > 0 ? e.self_seconds / total : 0;
    r.parallel = e.self_seconds > 0 ? std::min(1.0, e.self_parallel_seconds / e.self_seconds) : 0;
    // rows without a traffic model (they contain other rows) show no rates
    if (e.seconds > 0 && e.bytes > 0) {
      r.bytes_per_s = e.bytes / e.seconds;
      r.flops_per_s = e.flops / e.seconds;
    }
    counted += e.self_seconds;
    counted_parallel += e.self_parallel_seconds;
    rows.push_back(r);
  }
  ProfileRow other;
  other.kernel = "other";
  other.seconds = other.self_seconds = std::max(0.0, total - counted);
  other.share = total > 0 ? other.self_seconds / total : 0;
  const double other_parallel = parallel_seconds(launches_since_reset()) - counted_parallel;
  other.parallel = other.self_seconds > 0 ? std::clamp(other_parallel / other.self_seconds, 0.0, 1.0) : 0;
  rows.push_back(other);
  return rows;
}

namespace {
// the launches by kernel: the longest first, down to a thousandth of the
// run, the rest in one line
std::string kernel_launch_table(double total) {
  const std::vector<KernelLaunches> kernels = kernel_launches_since_reset();
  if (kernels.empty()) return "";
  std::string out =
      "\nlaunches by kernel (every launch of the run; where: threads = a parallel region, 1 thread = work\n"
      " below worth_threads, device = a target region, copy = between host and device memory)\n";
  char line[256];
  std::snprintf(line, sizeof line, "%-32s %-8s %8s %10s %7s %9s %9s %9s\n", "kernel", "where", "calls", "time [s]",
                "share", "us/call", "GB/s", "GFLOP/s");
  out += line;
  double in_launches = 0, rest = 0;
  long long rest_calls = 0, rest_rows = 0;
  for (const KernelLaunches& k : kernels) {
    in_launches += k.seconds;
    if (total > 0 && k.seconds < 1e-3 * total) {
      rest += k.seconds;
      rest_calls += k.calls;
      ++rest_rows;
      continue;
    }
    char gbs[16] = "-", gflops[16] = "-";
    if (k.seconds > 0 && k.bytes > 0) std::snprintf(gbs, sizeof gbs, "%.2f", k.bytes / k.seconds * 1e-9);
    if (k.seconds > 0 && k.flops > 0) std::snprintf(gflops, sizeof gflops, "%.2f", k.flops / k.seconds * 1e-9);
    std::snprintf(line, sizeof line, "%-32s %-8s %8lld %10.3f %6.1f%% %9.1f %9s %9s\n", k.kernel.c_str(),
                  to_string(k.ran), k.calls, k.seconds, total > 0 ? 100 * k.seconds / total : 0.0,
                  1e6 * k.seconds / double(k.calls), gbs, gflops);
    out += line;
  }
  if (rest_rows > 0) {
    std::snprintf(line, sizeof line, "(%lld more, each under 0.1 %% of the run: %lld calls, %.3f s)\n", rest_rows,
                  rest_calls, rest);
    out += line;
  }
  if (total > 0) {
    std::snprintf(line, sizeof line,
                  "in launches: %.3f s of the %.3f s (%.1f %%); GB/s and GFLOP/s from the kernels' modelled "
                  "traffic and flops\n",
                  in_launches, total, 100 * in_launches / total);
    out += line;
  }
  return out;
}
}  // namespace

std::string profile_table(double total) {
  std::string out;
  char line[256];
  std::snprintf(line, sizeof line, "%-22s %10s %10s %10s %7s %9s %9s %8s\n", "kernel", "calls", "time [s]",
                "self [s]", "share", "GB/s", "GFLOP/s", "parallel");
  out += line;
  for (const ProfileRow& r : profile_rows(total)) {
    char gbs[16] = "-", gflops[16] = "-", calls[24] = "-";
    if (r.bytes_per_s > 0) {
      std::snprintf(gbs, sizeof gbs, "%.2f", r.bytes_per_s * 1e-9);
      std::snprintf(gflops, sizeof gflops, "%.2f", r.flops_per_s * 1e-9);
    }
    if (r.calls > 0) std::snprintf(calls, sizeof calls, "%lld", r.calls);
    std::snprintf(line, sizeof line, "%-22s %10s %10.3f %10.3f %6.1f%% %9s %9s %7.0f%%\n", r.kernel.c_str(), calls,
                  r.seconds, r.self_seconds, 100 * r.share, gbs, gflops, 100 * r.parallel);
    out += line;
  }
  out += "(time: the row's whole time; self: less the rows timed inside it, e.g. the smoother less its\n"
         " applies; share: self / total, so the shares add up to 100 %; other: outside every timer;\n"
         " parallel: the part of self inside parallel regions (or on the device), the rest ran on one thread)\n";
  out += kernel_launch_table(total);
  // Amdahl's part: what more threads leave as it is
  const LaunchCounts since = launches_since_reset();
  if (total > 0) {
    const double serial = one_thread_seconds(total);
    std::snprintf(line, sizeof line,
                  "one thread: %.3f s of the %.3f s (%.1f %%): %.3f s in %lld launches below worth_threads, "
                  "%.3f s between launches; no thread count takes the run below it\n",
                  serial, total, 100 * serial / total, since.one_thread_seconds, since.one_thread,
                  std::max(0.0, serial - since.one_thread_seconds));
    out += line;
    if (since.device > 0) {
      std::snprintf(line, sizeof line, "on the device: %.3f s in %lld target regions (each until the device ends it)\n",
                    since.device_seconds, since.device);
      out += line;
    }
  }
  // the parallel regions by size: what the small ones cost each, against their work
  if (since.threaded > 0) {
    out += "parallel regions by modelled work (bytes + flops):";
    for (int k = 0; k < LaunchCounts::kSizes; ++k) {
      const double lo = kParallelWork * std::pow(10.0, k);
      char range[48];
      if (k + 1 == LaunchCounts::kSizes)
        std::snprintf(range, sizeof range, ">= %.0e", lo);
      else
        std::snprintf(range, sizeof range, "%.0e-%.0e", lo, 10 * lo);
      const long long n = since.by_size[k];
      std::snprintf(line, sizeof line, "%s %s: %lld, %.3f s (%.0f us, %.1e each)", k ? ";" : "", range, n,
                    since.by_size_seconds[k], n ? 1e6 * since.by_size_seconds[k] / double(n) : 0.0,
                    n ? since.by_size_work[k] / double(n) : 0.0);
      out += line;
    }
    out += "\n";
  }
  // the fork/join census (launch.hpp), and the Fields' block cache
  // (field.hpp), since the program started
  const LaunchCounts n = launch_counts();
  std::snprintf(line, sizeof line,
                "launches: %lld parallel regions on %d thread(s), %lld on one thread (below worth_threads), "
                "%lld on the device\n",
                n.threaded, omp_get_max_threads(), n.one_thread, n.device);
  out += line;
  for (Space s : {Space::host, Space::device}) {
    const BlockReuse b = block_reuse(s);
    if (b.requests == 0) continue;
    std::snprintf(line, sizeof line,
                  "%s blocks%s: %lld made, %lld of them reused (%.2f GB not %s again); at most %.2f GB in Fields\n",
                  to_string(s), s == Space::host ? " of 1 MiB and more" : "", b.requests, b.reused,
                  b.reused_bytes * 1e-9, s == Space::host ? "faulted in" : "allocated", b.peak_bytes * 1e-9);
    out += line;
  }
  return out;
}

}  // namespace tresca
