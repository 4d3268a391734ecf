// The elasticity apply's arithmetic for one band of node rows, and the FMA
// chains of perf/roofline's flop peak: the compute-bound work, compiled once
// per instruction set (kernels/isa.hpp). CMake builds this file several
// times, each with its own -march and its own TRESCA_ISA_NS (isa_baseline,
// isa_x86_64_v4); the program picks one at start.
//
// Nothing here may be shared with other translation units: every function
// is in this unit's own namespace or has internal linkage (the launches of
// the bands and the std:: templates stay in elasticity.cpp, compiled for
// the baseline; fma_chains' parallel region is outlined into a function of
// this namespace), so no AVX-512 copy of a shared function can reach the
// baseline's callers. tests/check_isa.py checks the linked programs for it.
#include "isa.hpp"
#include "simd.hpp"
#include "stencil_row.hpp"

#ifndef TRESCA_ISA_NS
#error "kernels/elasticity_isa.cpp is compiled by CMake with -DTRESCA_ISA_NS=<namespace> -DTRESCA_ISA_ID=<id>"
#endif

namespace tresca {
namespace TRESCA_ISA_NS {
namespace {

// Accumulates the groups [g, ge) whose nonzero outputs are the mask M.
// V is the target's native vector of Simd<T>::lanes values of T (simd.hpp);
// each input vector is loaded once and feeds the |M| outputs.
template <class T, int NV, int M>
inline void accumulate(const StencilGroupT<T>* g, const StencilGroupT<T>* ge, const T* x, Vec<T>* a0, Vec<T>* a1,
                       Vec<T>* a2) {
  using V = Vec<T>;
  constexpr int kLanes = Simd<T>::lanes;
  for (; g != ge; ++g) {
    const T* xp = x + g->off;
    const T c0 = g->c[0], c1 = g->c[1], c2 = g->c[2];
    V v[NV];
    for (int l = 0; l < NV; ++l) v[l] = *reinterpret_cast<const V*>(xp + kLanes * l);
    for (int l = 0; l < NV; ++l) {
      if (M & 1) a0[l] += c0 * v[l];
      if (M & 2) a1[l] += c1 * v[l];
      if (M & 4) a2[l] += c2 * v[l];
    }
  }
}

// Entries [i, i+W) of the row starting at node `row`, for the 3 output
// components of one stencil (f = first + 7*s), handed to put() (apply_out.hpp);
// xr = x + row. The first `done` entries are computed but not put (they
// were: a Chebyshev step's put may not run twice on an entry). Always
// inlined: GCC otherwise calls the smoother step's copy once a block, and
// the fused step at level 12 runs 5-12 % slower (RESULTS.md §0zj). dc: the
// step's weights of the run's class, or null (apply_out.hpp: dinv_at).
template <OutKind K, class T, int W>
__attribute__((always_inline)) inline void stencil_block(const StencilGroupT<T>* g, const std::int32_t* f,
                                                         const T* dc, const T* xr, const ApplyOut<T> o, const T* x,
                                                         index row, index N, index i, int done = 0) {
  using V = Vec<T>;
  constexpr int kLanes = Simd<T>::lanes;
  if constexpr (W % kLanes != 0) {
    // scalar path for runs shorter than one vector
    for (int l = 0; l < W; ++l) {
      T acc[3] = {0, 0, 0};
      for (const StencilGroupT<T>* q = g + f[0]; q != g + f[7]; ++q)
        for (int a = 0; a < 3; ++a) acc[a] += q->c[a] * xr[i + l + q->off];
      for (int a = 0; a < 3; ++a) {
        const index j = a * N + row + i + l;
        put<K>(o, x, j, acc[a], dinv_at<K, T>(o, dc, a, j));
      }
    }
  } else {
    constexpr int NV = W / kLanes;
    V a0[NV], a1[NV], a2[NV];
    for (int l = 0; l < NV; ++l) a0[l] = a1[l] = a2[l] = V{};
    const T* xi = xr + i;
    accumulate<T, NV, 1>(g + f[0], g + f[1], xi, a0, a1, a2);
    accumulate<T, NV, 2>(g + f[1], g + f[2], xi, a0, a1, a2);
    accumulate<T, NV, 3>(g + f[2], g + f[3], xi, a0, a1, a2);
    accumulate<T, NV, 4>(g + f[3], g + f[4], xi, a0, a1, a2);
    accumulate<T, NV, 5>(g + f[4], g + f[5], xi, a0, a1, a2);
    accumulate<T, NV, 6>(g + f[5], g + f[6], xi, a0, a1, a2);
    accumulate<T, NV, 7>(g + f[6], g + f[7], xi, a0, a1, a2);
    V* out[3] = {a0, a1, a2};
    if (done > 0) {  // (NV = 1: the run's last, overlapping vector)
      V lane;
      for (int l = 0; l < kLanes; ++l) lane[l] = T(l);
      const auto keep = lane < T(done);
      for (int a = 0; a < 3; ++a) {
        const index j = a * N + row + i;
        put_lanes<K>(o, x, j, out[a][0], dinv_at<K, V>(o, dc, a, j), keep);
      }
      return;
    }
    for (int a = 0; a < 3; ++a)
      for (int l = 0; l < NV; ++l) {
        const index j = a * N + row + i + kLanes * l;
        put<K>(o, x, j, out[a][l], dinv_at<K, V>(o, dc, a, j));
      }
  }
}

// `lead`: the offset from a node to its input that no row before it in the
// band's order read (one plane and one row on: apply_band)
template <OutKind K, class T>
inline void stencil_range(const StencilGroupT<T>* g, const std::int32_t* f, const T* dc, const T* xr,
                          const ApplyOut<T> o, const T* x, index row, index N, index i0, index i1, index lead) {
  constexpr int kLanes = Simd<T>::lanes;
  // three vectors per block: 9 accumulators + 3 inputs fit the 16 registers of
  // SSE/AVX2 (and AVX-512's 32); the width is measured (perf/RESULTS.md §0i)
  constexpr int kW = 3 * kLanes;
  constexpr int kLine = 64 / sizeof(T);  // entries a 64-byte line
  index i = i0;
  for (; i + kW <= i1; i += kW) {
    // The next block's lines that come from memory: the lead input row's
    // (every other input row was read by the rows before, and is in cache),
    // and for the smoother's step those of b and y, which its epilogue
    // otherwise misses on in a burst after the block's arithmetic. The
    // hardware's prefetchers alone leave the apply a third slower on
    // meshes that do not fit the caches (RESULTS.md §0p, §0zj).
    for (int a = 0; a < 3; ++a)
      for (int l = 0; l < kW; l += kLine) {
        const index j = a * N + i + kW + l;
        __builtin_prefetch(xr + lead + j);
        if constexpr (is_step(K)) {
          __builtin_prefetch(o.b + row + j);
          if (!dc) __builtin_prefetch(o.dinv + row + j);
          __builtin_prefetch(o.y + row + j, 1);  // (for writing, also where the step does not read it)
        }
      }
    stencil_block<K, T, kW>(g, f, dc, xr, o, x, row, N, i);
  }
  for (; i + kLanes <= i1; i += kLanes) stencil_block<K, T, kLanes>(g, f, dc, xr, o, x, row, N, i);
  if (i < i1 && i1 - i0 >= kLanes) {
    // finish with one overlapping vector: computes a few entries again, puts the new ones
    stencil_block<K, T, kLanes>(g, f, dc, xr, o, x, row, N, i1 - kLanes, int(i - (i1 - kLanes)));
    return;
  }
  for (; i < i1; ++i) stencil_block<K, T, 1>(g, f, dc, xr, o, x, row, N, i);
}

}  // namespace

template <class T>
void apply_band(const StencilView<T>& v, const T* x, const ApplyOut<T>& o, const RowBlock& rows) {
  const index nx = v.g.nx(), ny = v.g.ny(), N = v.g.nodes();
  // rows go in z, then y order: row (iy, iz) is the first to read row
  // (iy + 1, iz + 1) of x (a prefetch only: past the grid's end it reads nothing)
  const index lead = nx * ny + nx;
  with_kind(o, [&](auto kind) {
    constexpr OutKind K = decltype(kind)::value;
    for (index iz = rows.z_begin; iz < rows.z_end; ++iz)
      for (index iy = rows.y_begin; iy < rows.y_end; ++iy)
        sweep_row<K>(v, nx, ny, N, iz, iy, x, o,
                     [&](const std::int32_t* f, const T* xr, index row, index i0, index i1, const T* dc) {
                       stencil_range<K, T>(v.groups, f, dc, xr, o, x, row, N, i0, i1, lead);
                     });
  });
}

template <class T>
double fma_chains(long iterations) {
  using V = Vec<T>;
  constexpr int K = kFmaChains;
  double total = 0;
#pragma omp parallel reduction(+ : total)
  {
    V acc[K];
    for (int k = 0; k < K; ++k) acc[k] = V{} + T(k + 1) * T(1e-3);
    const V a = V{} + T(0.999999), c = V{} + T(1e-7);
    for (long it = 0; it < iterations; ++it)
      for (int k = 0; k < K; ++k) acc[k] = acc[k] * a + c;
    for (int k = 0; k < K; ++k)
      for (int l = 0; l < Simd<T>::lanes; ++l) total += double(acc[k][l]);
  }
  return total;
}

extern const IsaKernels kernels;
const IsaKernels kernels = {TRESCA_ISA_ID,      simd_isa(),          kSimdBytes,        &apply_band<double>,
                            &apply_band<float>, &fma_chains<double>, &fma_chains<float>};

}  // namespace TRESCA_ISA_NS
}  // namespace tresca
