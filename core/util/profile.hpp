// Per-kernel call counts, wall time, and modelled bytes/flops (the models are
// stated in each kernel's header). `tresca --profile` prints the table.
// Timers are cheap (omp_get_wtime) and always on.
#pragma once
#include <string>
#include <vector>

#include "kernels/types.hpp"

namespace tresca {

enum class Kernel : int {
  apply, apply_boundary, diagonal, smoother, prolongate, restrict_, coarse_solve, vector, contact_maps,
  inner_cg, outer_cg, host_levels, count
};
const char* kernel_name(Kernel k);

struct ProfileEntry {
  long long calls = 0;
  double seconds = 0, bytes = 0, flops = 0;
  double self_seconds = 0;  // less the time of the timers nested in it (smoother: less its applies)
  double parallel_seconds = 0, self_parallel_seconds = 0;  // of those, inside parallel or target regions
};

// One row of the profile. Timers nest (an inner CG contains applies, the
// smoother contains applies): `seconds` is a row's whole time, `self_seconds`
// the part no nested row counts, and `share` = self / total, so the shares
// of the rows and of "other" (outside every timer: setup, Newton's own
// bookkeeping, output) add up to 100 %. Rates use the whole time and are 0
// where a row has no traffic model. `parallel` is the share of the row's
// self time spent inside parallel regions or on the device (launch.hpp):
// the rest ran on one host thread, and more threads do not shorten it.
struct ProfileRow {
  std::string kernel;
  long long calls = 0;
  double seconds = 0, self_seconds = 0, share = 0, bytes_per_s = 0, flops_per_s = 0, parallel = 0;
};
std::vector<ProfileRow> profile_rows(double total_seconds);
// forget what was timed so far (a driver running several solves: before each)
void profile_reset();
// the launch census (kernels/launch.hpp) since the last profile_reset (since
// the start, if none): how many launches, and their seconds threaded, on
// one thread and on the device
struct LaunchCounts;
LaunchCounts launches_since_reset();
struct KernelLaunches;
// of a run of `total` seconds since the last profile_reset, the part outside
// every parallel region and target region: what ran on one host thread
double one_thread_seconds(double total);
// every kernel's launches since the last profile_reset (launches_by_kernel,
// kernels/launch.hpp), each (kernel, where it ran) once, the longest first
std::vector<KernelLaunches> kernel_launches_since_reset();
// the rows as a table: calls, time, self time, share, GB/s and GFLOP/s; then
// the launches by kernel, and the launch census
std::string profile_table(double total_seconds);

double wall_time();
// the shortest of `reps` wall-clock timings of f() (the minimum filters out
// interruptions by other processes)
template <class F>
double best_time(int reps, F&& f) {
  double best = 1e300;
  for (int r = 0; r < reps; ++r) {
    const double t0 = wall_time();
    f();
    const double t = wall_time() - t0;
    best = t < best ? t : best;
  }
  return best;
}
// peak resident memory of this process so far, in bytes (getrusage)
double peak_memory_bytes();
// STREAM triad a = b + s c over n doubles with the current thread count,
// through the launch layer: bytes per second as STREAM counts them (24 per
// entry, no write-allocate), the best of `reps` after a warm-up. The
// machine's own bandwidth, the yardstick of the roofline and of scaling's
// bandwidth-ideal speed-up. Throws if the triad computes a wrong value.
double triad_bandwidth(index n, int reps);

// Times a scope as kernel k. Timers are made and ended on the driver's
// (serial) thread, innermost last; each one knows the timer it runs in.
class ScopedTimer {
 public:
  // cost: the kernel's modelled traffic and flops (n * kSomeCost)
  explicit ScopedTimer(Kernel k, Cost cost = {});
  ~ScopedTimer();
  ScopedTimer(const ScopedTimer&) = delete;
  ScopedTimer& operator=(const ScopedTimer&) = delete;

 private:
  Kernel k_;
  double b_, f_, t0_, parallel0_;
  double nested_ = 0, nested_parallel_ = 0;  // the time (and parallel time) of the timers ended inside this one
  ScopedTimer* outer_;
};

}  // namespace tresca
