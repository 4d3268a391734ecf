// One node row of the elasticity apply, shared by its forms: the banded CPU
// apply (kernels/elasticity_isa.cpp, once per instruction set) and the row
// form of the device (elasticity.cpp). Internal to kernels/.
//
// Everything here has internal linkage (an unnamed namespace): each
// translation unit that includes it keeps its own copy, compiled for its own
// instruction set, so the linker never picks an AVX-512 copy for the
// baseline's callers (kernels/isa.hpp).
#pragma once
#include <cstdint>

#include "apply_out.hpp"
#include "elasticity.hpp"

namespace tresca {
namespace {

// the per-axis class bits of a node (ElasticityStencilT::cls)
enum : std::uint8_t { kHasL = 1, kHasR = 2, kDropL = 4, kDropR = 8, kSelf = 16 };

// One node row (iz, iy) of an apply of x (apply_out.hpp: y = K x, b - K x
// or a Chebyshev step; K = kind(out)) over its x-runs: a run of nodes on a constrained face
// (or the whole row on one) is the identity there (v = x, a step's weight
// 1); every other run
// hands its stencil (f = first + 7 s), x offset to the row's first node,
// that node's index and the step's Jacobi weights of its class (dc =
// inv_center + 3 s; null on the bottom plane: dinv_at) to run(f, xr, row,
// i0, i1, dc). The banded apply and its row form differ only in `run` and
// in how rows are launched.
template <OutKind K, class T, class Run>
inline void sweep_row(const StencilView<T>& k, index nx, index ny, index N, index iz, index iy, const T* x,
                      const ApplyOut<T> out, const Run& run) {
  const std::uint8_t cy = k.cls[1][iy], cz = k.cls[2][iz];
  const index row = nx * (iy + ny * iz);
  const bool row_fixed = (cy & kSelf) || (cz & kSelf);
  const T* xr = x + row;
  for (index r = 0; r < k.nruns; ++r) {
    const index i0 = k.run_begin[r], i1 = k.run_begin[r + 1];
    const std::uint8_t cx = k.cls[0][i0];
    if (row_fixed || (cx & kSelf)) {  // (the identity's rows: a step's weight 1)
      for (int a = 0; a < 3; ++a)
#pragma omp simd
        for (index i = i0; i < i1; ++i) put<K>(out, x, a * N + row + i, xr[a * N + i], T(1));
      continue;
    }
    const std::int32_t s = k.slot[(cx * 32 + cy) * 32 + cz];
    run(k.first + 7 * s, xr, row, i0, i1, iz == 0 ? nullptr : k.inv_center + 3 * s);
  }
}

}  // namespace
}  // namespace tresca
