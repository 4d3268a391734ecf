// Where a kernel runs and where its vectors live: the one place that decides.
//
// Every kernel in kernels/ states its work as an index range, its modelled
// Cost and a body (a lambda over plain pointers), and hands them to one of
// the launchers below; no kernel starts threads itself. This is the seam of
// the backends (in the spirit of a `parallel_for` over an index range):
//
//   - host (this file): OpenMP threads when the modelled work is worth it
//     (worth_threads, types.hpp), schedule(static) so every sweep gives each
//     thread the same entries, and so the pages it touched first;
//   - the `_ref` twins are plain serial loops beside each kernel (the
//     independent oracle of the tests, not a backend);
//   - the device (a TRESCA_OFFLOAD build, below): a second branch inside
//     the same launchers, `omp target teams distribute parallel for [simd]`
//     over the same bodies. Nothing above kernels/ names OpenMP's loop
//     constructs.
//
// Field<T> is the storage of everything the linear machinery sweeps: the
// operators' stencils and diagonals, every multigrid level's vectors, the
// Krylov vectors. Code that owns such a vector declares it a Field.
#pragma once
#include "types.hpp"

#include <omp.h>

#include <algorithm>
#include <string>
#include <vector>

namespace tresca {

// Host storage of a Field: large arrays (>= 1 MiB) are aligned to 2 MiB and
// marked MADV_HUGEPAGE, so where the kernel's transparent-huge-page mode is
// "madvise" (Debian's default) their first touch costs one page fault per
// 2 MiB instead of per 4 KiB (perf/RESULTS.md §0d, §0k). Smaller arrays come
// from operator new as usual.
void* field_allocate(std::size_t bytes);
void field_deallocate(void* p, std::size_t bytes) noexcept;

template <class T>
struct FieldAllocator {
  using value_type = T;
  FieldAllocator() = default;
  template <class U>
  FieldAllocator(const FieldAllocator<U>&) noexcept {}
  T* allocate(std::size_t n) { return static_cast<T*>(field_allocate(n * sizeof(T))); }
  void deallocate(T* p, std::size_t n) noexcept { field_deallocate(p, n * sizeof(T)); }
  template <class U>
  bool operator==(const FieldAllocator<U>&) const noexcept { return true; }
  template <class U>
  bool operator!=(const FieldAllocator<U>&) const noexcept { return false; }
};

template <class T>
using Field = std::vector<T, FieldAllocator<T>>;

// The device backend (a build with TRESCA_OFFLOAD, CMake option of that
// name: g++-12 with gcc-12-offload-nvptx). While launch_on_device() is
// true, for_each_entry, sum_over_blocks and the n1 x n0 for_each_block run
// their bodies as OpenMP target regions on the default device, over
// pointers that must then be device pointers (device_allocate); without a
// GPU the target regions run on the host. The 1D for_each_block (the banded
// CPU apply) and the launcher with scratch (the transfers) have no device
// branch yet, nor has Field storage: issue 22's next steps. Without
// TRESCA_OFFLOAD, launch_on_device() is false and set_launch_on_device
// refuses true.
bool launch_on_device();
void set_launch_on_device(bool on);  // throws std::invalid_argument if the build has no offload
bool offload_built();                // whether this build has TRESCA_OFFLOAD
// device memory of the default device (omp_target_alloc; the host's when
// there is none), and copies to and from it
void* device_allocate(std::size_t bytes);
void device_free(void* p) noexcept;
void copy_to_device(void* device, const void* host, std::size_t bytes);
void copy_from_device(void* host, const void* device, std::size_t bytes);
// "device 0 of 1 (OpenMP offload)", or "none: target regions run on the host"
std::string device_description();

// How many workers a launch has (threads on the host): a kernel that cuts
// its range into cache-sized blocks makes at least one block per worker.
inline index launch_width() { return omp_get_max_threads(); }

// body(i) for every i in [0, n), independent entries vectorised across i.
template <class Body>
inline void for_each_entry(index n, Cost per_entry, const Body& body) {
#ifdef TRESCA_OFFLOAD
  if (launch_on_device()) {
    // a copy of the body, mapped implicitly: its captures (device pointers,
    // scalars) travel by value (GCC 12 fails on a lambda in a map or
    // firstprivate clause: an internal compiler error)
    Body b = body;
#pragma omp target teams distribute parallel for simd
    for (index i = 0; i < n; ++i) b(i);
    return;
  }
#endif
#pragma omp parallel for simd schedule(static) if (parallel : worth_threads(double(n) * per_entry))
  for (index i = 0; i < n; ++i) body(i);
}

// body(b) for every block b in [0, n): independent blocks of work (rows,
// bands of rows), each vectorised inside by its own body. `work` is the
// whole launch's modelled cost.
template <class Body>
inline void for_each_block(index n, Cost work, const Body& body) {
#pragma omp parallel for schedule(static) if (worth_threads(work))
  for (index b = 0; b < n; ++b) body(b);
}

// body(j, i) for every block of an n1 x n0 range (j slow, i fast).
template <class Body>
inline void for_each_block(index n1, index n0, Cost work, const Body& body) {
#ifdef TRESCA_OFFLOAD
  if (launch_on_device()) {  // one block per (team) thread; the body's own `omp simd` loops in its lanes
    Body b = body;
#pragma omp target teams distribute parallel for collapse(2)
    for (index j = 0; j < n1; ++j)
      for (index i = 0; i < n0; ++i) b(j, i);
    return;
  }
#endif
#pragma omp parallel for collapse(2) schedule(static) if (worth_threads(work))
  for (index j = 0; j < n1; ++j)
    for (index i = 0; i < n0; ++i) body(j, i);
}

// The same, with `scratch` entries of T private to each worker for the
// launch (allocated once per launch, not per block): body(j, i, scratch).
template <class T, class Body>
inline void for_each_block_with_scratch(index n1, index n0, index scratch, Cost work, const Body& body) {
#pragma omp parallel if (worth_threads(work))
  {
    std::vector<T> buffer(scratch);
    T* s = buffer.data();
#pragma omp for collapse(2) schedule(static)
    for (index j = 0; j < n1; ++j)
      for (index i = 0; i < n0; ++i) body(j, i, s);
  }
}

// Sum of block(i0, i1) over the fixed blocks [b*width, (b+1)*width) of
// [0, n): the blocks in parallel, their sums added in order afterwards, so
// the result is bitwise the same for any number of workers. Each caller's
// block is a loop over plain pointers (vectorised with contiguous loads).
template <class Block>
inline real sum_over_blocks(index n, index width, Cost per_entry, const Block& block) {
  const index nb = (n + width - 1) / width;
  constexpr index kStack = 256;
  real stack[kStack];
  std::vector<real> heap;
  real* part = stack;
  if (nb > kStack) {
    heap.resize(nb);
    part = heap.data();
  }
#ifdef TRESCA_OFFLOAD
  if (launch_on_device()) {
    Block bl = block;
#pragma omp target teams distribute parallel for map(from : part[0 : nb])
    for (index b = 0; b < nb; ++b) part[b] = bl(b * width, b + 1 < nb ? (b + 1) * width : n);
  } else
#endif
#pragma omp parallel for schedule(static) if (worth_threads(double(n) * per_entry))
  for (index b = 0; b < nb; ++b) part[b] = block(b * width, std::min(n, (b + 1) * width));
  real s = 0;
  for (index b = 0; b < nb; ++b) s += part[b];
  return s;
}

}  // namespace tresca
