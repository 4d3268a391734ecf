// Scalar and index types used everywhere. Sizes that exceed 2^31 at large
// mesh levels (dof counts, flat offsets) are 64-bit.
#pragma once
#include <cassert>
#include <cstdint>

namespace tresca {
using real = double;
using index = std::int64_t;

// Contracts. TRESCA_ASSERT: cheap checks at kernel and operator entry points
// (sizes, ranges, aliasing), compiled out in Release (NDEBUG) so hot paths pay
// nothing; run the tests in a Debug build to exercise them. Checks at the API
// boundary (drivers, solvers' public functions) are always on and throw
// std::invalid_argument naming the value.
#define TRESCA_ASSERT(cond) assert(cond)

// Modelled cost of a kernel per work item: bytes moved to or from memory (no
// write-allocate) and flops. Each kernel header states its own, once; the
// profiler, benchmarks and perf/roofline scale them by the item count.
struct Cost {
  double bytes = 0, flops = 0;
};
constexpr Cost operator*(double n, Cost c) { return {n * c.bytes, n * c.flops}; }
constexpr Cost operator+(Cost a, Cost b) { return {a.bytes + b.bytes, a.flops + b.flops}; }
// When a kernel starts threads: only if its modelled work is worth it. A
// parallel region costs a few microseconds (more when the threads have gone
// to sleep); 2e5 bytes + flops is about 20 us of one core's work. Every
// kernel applies this one rule to its own Cost (an OpenMP `if` clause).
constexpr double kParallelWork = 2e5;
constexpr bool worth_threads(Cost c) { return c.bytes + c.flops >= kParallelWork; }

// the cost models are stated for double fields; fields of T move sizeof(T)/8 of the bytes
template <class T>
constexpr Cost in_precision(Cost c) {
  return {c.bytes * double(sizeof(T)) / double(sizeof(real)), c.flops};
}
}  // namespace tresca
