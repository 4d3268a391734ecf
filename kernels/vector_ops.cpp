#include "vector_ops.hpp"

#include "simd.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace tresca {

namespace {
// Sums block(i0, i1) over the fixed blocks [b*kDotBlock, (b+1)*kDotBlock) in
// parallel, then adds the block sums serially: bitwise the same result for
// any thread count. Each caller writes its block loop over plain pointers so
// the compiler vectorises it with contiguous loads on every target (a per-
// entry callback was vectorised with gathers and a spilled sum under AVX-512).
template <class Block>
real blocked_sum(index n, Cost per_entry, Block block) {
  const index nb = (n + kDotBlock - 1) / kDotBlock;
  constexpr index kStack = 256;
  real stack[kStack];
  std::vector<real> heap;
  real* part = stack;
  if (nb > kStack) {
    heap.resize(nb);
    part = heap.data();
  }
#pragma omp parallel for schedule(static) if (worth_threads(double(n) * per_entry))
  for (index b = 0; b < nb; ++b) part[b] = block(b * kDotBlock, std::min(n, (b + 1) * kDotBlock));
  real s = 0;
  for (index b = 0; b < nb; ++b) s += part[b];
  return s;
}
}  // namespace

// Reductions use the target's vectors explicitly (simd.hpp): two independent
// vector sums per block, a scalar tail. (GCC 12's `omp simd reduction` was
// vectorised with gathers and a sum spilled to the stack every iteration
// under -march=native on AVX-512: 4x slower than the AVX2 build.)
using V = Vec<real>;
constexpr index kL = Simd<real>::lanes;
inline V load(const real* p) { return *reinterpret_cast<const V*>(p); }
inline void store(real* p, V v) { *reinterpret_cast<V*>(p) = v; }
inline real hsum(V v) {
  real s = 0;
  for (index l = 0; l < kL; ++l) s += v[l];
  return s;
}

real dot(index n, const real* x, const real* y) {
  return blocked_sum(n, kDotCost, [x, y](index i0, index i1) {
    V s0{}, s1{};
    index i = i0;
    for (; i + 2 * kL <= i1; i += 2 * kL) {
      s0 += load(x + i) * load(y + i);
      s1 += load(x + i + kL) * load(y + i + kL);
    }
    for (; i + kL <= i1; i += kL) s0 += load(x + i) * load(y + i);
    real s = hsum(s0 + s1);
    for (; i < i1; ++i) s += x[i] * y[i];
    return s;
  });
}

real dot_ref(index n, const real* x, const real* y) {
  real s = 0;
  for (index i = 0; i < n; ++i) s += x[i] * y[i];
  return s;
}

real norm2(index n, const real* x) { return std::sqrt(dot(n, x, x)); }

void axpy(index n, real a, const real* x, real* y) {
#pragma omp parallel for simd schedule(static) if (parallel : worth_threads(double(n) * kAxpyCost))
  for (index i = 0; i < n; ++i) y[i] += a * x[i];
}
void xpay(index n, const real* x, real a, real* y) {
#pragma omp parallel for simd schedule(static) if (parallel : worth_threads(double(n) * kXpayCost))
  for (index i = 0; i < n; ++i) y[i] = x[i] + a * y[i];
}
void copy(index n, const real* x, real* y) {
#pragma omp parallel for simd schedule(static) if (parallel : worth_threads(double(n) * kCopyCost))
  for (index i = 0; i < n; ++i) y[i] = x[i];
}
template <class T>
void fill(index n, T v, T* y) {
#pragma omp parallel for simd schedule(static) if (parallel : worth_threads(double(n) * in_precision<T>(kFillCost)))
  for (index i = 0; i < n; ++i) y[i] = v;
}
void scale(index n, real a, real* y) {
#pragma omp parallel for simd schedule(static) if (parallel : worth_threads(double(n) * kScaleCost))
  for (index i = 0; i < n; ++i) y[i] *= a;
}
void hadamard(index n, const real* d, const real* x, real* y) {
#pragma omp parallel for simd schedule(static) if (parallel : worth_threads(double(n) * kHadamardCost))
  for (index i = 0; i < n; ++i) y[i] = d[i] * x[i];
}

real cg_update(index n, real a, const real* p, const real* q, real* x, real* r) {
  // fused in blocks so that r is still in cache (registers) when r.r is formed
  return blocked_sum(n, kCgUpdateCost, [=](index i0, index i1) {
    V s0{};
    index i = i0;
    for (; i + kL <= i1; i += kL) {
      store(x + i, load(x + i) + a * load(p + i));
      const V ri = load(r + i) - a * load(q + i);
      store(r + i, ri);
      s0 += ri * ri;
    }
    real s = hsum(s0);
    for (; i < i1; ++i) {
      x[i] += a * p[i];
      r[i] -= a * q[i];
      s += r[i] * r[i];
    }
    return s;
  });
}

real cg_update_ref(index n, real a, const real* p, const real* q, real* x, real* r) {
  for (index i = 0; i < n; ++i) {
    x[i] += a * p[i];
    r[i] -= a * q[i];
  }
  return dot_ref(n, r, r);
}

template <class To, class From>
void convert(index n, const From* x, To* y) {
#pragma omp parallel for simd schedule(static) if (parallel : worth_threads(double(n) * Cost{double(sizeof(From) + sizeof(To)), 0}))
  for (index i = 0; i < n; ++i) y[i] = To(x[i]);
}

template <class T>
void cheb_update(index n, T s, T t, const T* dinv, const T* r, T* d, T* x) {
#pragma omp parallel for simd schedule(static) if (parallel : worth_threads(double(n) * in_precision<T>(kChebUpdateCost)))
  for (index i = 0; i < n; ++i) {
    d[i] = s * d[i] + t * dinv[i] * r[i];
    x[i] += d[i];
  }
}

template <class T>
void cheb_first(index n, T t, const T* dinv, const T* b, T* d, T* x) {
#pragma omp parallel for simd schedule(static) if (parallel : worth_threads(double(n) * in_precision<T>(kChebFirstCost)))
  for (index i = 0; i < n; ++i) x[i] = d[i] = t * dinv[i] * b[i];
}

template void fill<double>(index, double, double*);
template void fill<float>(index, float, float*);
template void convert<float, double>(index, const double*, float*);
template void convert<double, float>(index, const float*, double*);
template void cheb_update<double>(index, double, double, const double*, const double*, double*, double*);
template void cheb_update<float>(index, float, float, const float*, const float*, float*, float*);
template void cheb_first<double>(index, double, const double*, const double*, double*, double*);
template void cheb_first<float>(index, float, const float*, const float*, float*, float*);


}  // namespace tresca
