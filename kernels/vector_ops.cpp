#include "vector_ops.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace tresca {

namespace {
template <class F>
real blocked_sum(index n, F term) {
  const index nb = (n + kDotBlock - 1) / kDotBlock;
  constexpr index kStack = 256;
  real stack[kStack];
  std::vector<real> heap;
  real* part = stack;
  if (nb > kStack) {
    heap.resize(nb);
    part = heap.data();
  }
#pragma omp parallel for schedule(static) if (nb > 4)
  for (index b = 0; b < nb; ++b) {
    const index i0 = b * kDotBlock, i1 = std::min(n, i0 + kDotBlock);
    real s = 0;
#pragma omp simd reduction(+ : s)
    for (index i = i0; i < i1; ++i) s += term(i);
    part[b] = s;
  }
  real s = 0;
  for (index b = 0; b < nb; ++b) s += part[b];
  return s;
}
}  // namespace

real dot(index n, const real* x, const real* y) {
  return blocked_sum(n, [=](index i) { return x[i] * y[i]; });
}

real dot_ref(index n, const real* x, const real* y) {
  real s = 0;
  for (index i = 0; i < n; ++i) s += x[i] * y[i];
  return s;
}

real norm2(index n, const real* x) { return std::sqrt(dot(n, x, x)); }

void axpy(index n, real a, const real* x, real* y) {
#pragma omp parallel for simd schedule(static)
  for (index i = 0; i < n; ++i) y[i] += a * x[i];
}
void xpay(index n, const real* x, real a, real* y) {
#pragma omp parallel for simd schedule(static)
  for (index i = 0; i < n; ++i) y[i] = x[i] + a * y[i];
}
void copy(index n, const real* x, real* y) {
#pragma omp parallel for simd schedule(static)
  for (index i = 0; i < n; ++i) y[i] = x[i];
}
void fill(index n, real v, real* y) {
#pragma omp parallel for simd schedule(static)
  for (index i = 0; i < n; ++i) y[i] = v;
}
void scale(index n, real a, real* y) {
#pragma omp parallel for simd schedule(static)
  for (index i = 0; i < n; ++i) y[i] *= a;
}
void hadamard(index n, const real* d, const real* x, real* y) {
#pragma omp parallel for simd schedule(static)
  for (index i = 0; i < n; ++i) y[i] = d[i] * x[i];
}

real cg_update(index n, real a, const real* p, const real* q, real* x, real* r) {
  // fused in blocks so that r is still in cache when r.r is formed
  return blocked_sum(n, [=](index i) {
    x[i] += a * p[i];
    r[i] -= a * q[i];
    return r[i] * r[i];
  });
}

real cg_update_ref(index n, real a, const real* p, const real* q, real* x, real* r) {
  for (index i = 0; i < n; ++i) {
    x[i] += a * p[i];
    r[i] -= a * q[i];
  }
  return dot_ref(n, r, r);
}

void cheb_update(index n, real s, real t, const real* dinv, const real* r, real* d, real* x) {
#pragma omp parallel for simd schedule(static)
  for (index i = 0; i < n; ++i) {
    d[i] = s * d[i] + t * dinv[i] * r[i];
    x[i] += d[i];
  }
}

void cheb_first(index n, real t, const real* dinv, const real* b, real* d, real* x) {
#pragma omp parallel for simd schedule(static)
  for (index i = 0; i < n; ++i) x[i] = d[i] = t * dinv[i] * b[i];
}

bool all_finite(index n, const real* x) {
  return blocked_sum(n, [=](index i) { return std::isfinite(x[i]) ? real(0) : real(1); }) == 0;
}

}  // namespace tresca
