// Per-kernel call counts, wall time, and modelled bytes/flops (the models are
// stated in each kernel's header). `tresca --profile` prints the table.
// Timers are cheap (omp_get_wtime) and always on.
#pragma once
#include <string>

#include "kernels/types.hpp"

namespace tresca {

enum class Kernel : int {
  apply, apply_boundary, diagonal, smoother, prolongate, restrict_, coarse_solve, vector, contact_maps,
  inner_cg, outer_cg, count
};
const char* kernel_name(Kernel k);

struct ProfileEntry {
  long long calls = 0;
  double seconds = 0, bytes = 0, flops = 0;
};

void profile_add(Kernel k, double seconds, double bytes, double flops);
// Table with calls, time, share of `total_seconds`, GB/s and GFLOP/s.
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

class ScopedTimer {
 public:
  // cost: the kernel's modelled traffic and flops (n * kSomeCost)
  explicit ScopedTimer(Kernel k, Cost cost = {}) : k_(k), b_(cost.bytes), f_(cost.flops), t0_(wall_time()) {}
  ~ScopedTimer() { profile_add(k_, wall_time() - t0_, b_, f_); }
  ScopedTimer(const ScopedTimer&) = delete;
  ScopedTimer& operator=(const ScopedTimer&) = delete;

 private:
  Kernel k_;
  double b_, f_, t0_;
};

}  // namespace tresca
