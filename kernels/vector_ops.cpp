#include "vector_ops.hpp"

#include "launch.hpp"
#include "simd.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace tresca {


// Reductions use the target's vectors explicitly (simd.hpp): two independent
// vector sums per block, a scalar tail. (GCC 12 vectorised `omp simd
// reduction` badly under -march=native on AVX-512: perf/RESULTS.md §0i.)
using V = Vec<real>;
constexpr index kL = Simd<real>::lanes;
inline V load(const real* p) { return *reinterpret_cast<const V*>(p); }
inline void store(real* p, V v) { *reinterpret_cast<V*>(p) = v; }
inline real hsum(V v) {
  real s = 0;
  for (index l = 0; l < kL; ++l) s += v[l];
  return s;
}
// kL entries from p as doubles (floats widened), and stored as floats
typedef float HalfV __attribute__((vector_size(kSimdBytes / 2), aligned(alignof(float)), may_alias));
inline V load_real(const real* p) { return load(p); }
inline V load_real(const float* p) { return __builtin_convertvector(*reinterpret_cast<const HalfV*>(p), V); }
inline void store_float(float* p, V v) { *reinterpret_cast<HalfV*>(p) = __builtin_convertvector(v, HalfV); }

// The sum over [i0, i1) of products in double, in the dot's order (a
// reduction's block on the host): two vector sums over pairs of vectors,
// then one, then the scalar tail. vterm(i) gives the factors of the kL
// products from i, sterm(i) those of one; a term may store as it goes (the
// CG's fused starts). The products are added here only, each fused
// (std::fma in the tail; GCC contracts the vectors' a * b + s the same way
// in every instance), so that a term whose factors are dot's gives dot's bits.
struct VFactors {  // of kL products
  V a, b;
};
struct Factors {  // of one
  real a, b;
};
template <class VTerm, class STerm>
real block_sum(index i0, index i1, const VTerm& vterm, const STerm& sterm) {
  V s0{}, s1{};
  auto add = [&](V& s, index i) {
    const auto [a, b] = vterm(i);
    s += a * b;
  };
  index i = i0;
  for (; i + 2 * kL <= i1; i += 2 * kL) {
    add(s0, i);
    add(s1, i + kL);
  }
  for (; i + kL <= i1; i += kL) add(s0, i);
  real s = hsum(s0 + s1);
  for (; i < i1; ++i) {
    const auto [a, b] = sterm(i);
    s = std::fma(a, b, s);
  }
  return s;
}

// a block_sum tail's term as sum_over_blocks' entry (the device's form):
// the product of its factors
template <class STerm>
auto product_of(const STerm& sterm) {
  return [=](index i) {
    const Factors f = sterm(i);
    return f.a * f.b;
  };
}

// the factors of entry i's product in x.y: x_i and y_i, or with weights w, w_i y_i
template <bool Weighted, class TX, class T>
auto dot_term(const TX* x, const T* w, const T* y) {
  return [=](index i) { return Factors{real(x[i]), Weighted ? real(w[i]) * real(y[i]) : real(y[i])}; };
}

// The sum over [i0, i1) of x_i y_i, or with weights w of x_i (w_i y_i)
template <bool Weighted, class TX, class T>
real block_dot(index i0, index i1, const TX* x, const T* w, const T* y) {
  return block_sum(
      i0, i1,
      [=](index i) {
        if constexpr (Weighted)
          return VFactors{load_real(x + i), load_real(w + i) * load_real(y + i)};
        else
          return VFactors{load_real(x + i), load_real(y + i)};
      },
      dot_term<Weighted>(x, w, y));
}

template <class TX, class TY>
real dot(index n, const TX* x, const TY* y) {
  const char* name = sizeof(TX) == sizeof(TY) ? precision_name<TY>("dot", "dot (float)") : "dot (double, float)";
  const Cost cost = sizeof(TX) == sizeof(TY) ? in_precision<TY>(kDotCost) : kDotFloatYCost;
  return sum_over_blocks(name, n, kDotBlock, cost,
                         [x, y](index i0, index i1) { return block_dot<false>(i0, i1, x, y, y); },
                         product_of(dot_term<false>(x, y, y)));
}

template <class T>
real dot_ref(index n, const T* x, const T* y) {
  real s = 0;
  for (index i = 0; i < n; ++i) s += real(x[i]) * real(y[i]);
  return s;
}

real norm2(index n, const real* x) { return std::sqrt(dot(n, x, x)); }

void axpy(index n, real a, const real* x, real* y) {
  for_each_entry("axpy", n, kAxpyCost, [=](index i) { y[i] += a * x[i]; });
}
void xpay(index n, const real* x, real a, real* y) {
  for_each_entry("xpay", n, kXpayCost, [=](index i) { y[i] = x[i] + a * y[i]; });
}
void xpay(index n, const float* x, real a, real* y) {
  for_each_entry("xpay (float x)", n, kXpayFloatXCost,
                 [=](index i) { y[i] = real(x[i]) + a * y[i]; });
}
void copy(index n, const real* x, real* y) {
  for_each_entry("copy", n, kCopyCost, [=](index i) { y[i] = x[i]; });
}
template <class T>
void fill(index n, T v, T* y) {
  for_each_entry(precision_name<T>("fill", "fill (float)"), n, in_precision<T>(kFillCost), [=](index i) { y[i] = v; });
}
void scale(index n, real a, real* y) {
  for_each_entry("scale", n, kScaleCost, [=](index i) { y[i] *= a; });
}
void hadamard(index n, const real* d, const real* x, real* y) {
  for_each_entry("hadamard", n, kHadamardCost, [=](index i) { y[i] = d[i] * x[i]; });
}
void triad(index n, const real* b, real s, const real* c, real* a) {
  for_each_entry("triad", n, kTriadCost, [=](index i) { a[i] = b[i] + s * c[i]; });
}

namespace {
// body(k) at entry k of each of the three runs, one launch
template <class Body>
void for_each_component_entry(const char* kernel, const ComponentRuns& r, Cost per_entry, const Body& body) {
  const index N = r.N, first = r.first;
  for_each_entry(kernel, r.count, 3 * per_entry, [=](index i) {
    body(first + i);
    body(N + first + i);
    body(2 * N + first + i);
  });
}
}  // namespace

void axpy(const ComponentRuns& r, real a, const real* x, real* y) {
  for_each_component_entry("axpy (component runs)", r, kAxpyCost, [=](index k) { y[k] += a * x[k]; });
}
void copy(const ComponentRuns& r, const real* x, real* y) {
  for_each_component_entry("copy (component runs)", r, kCopyCost, [=](index k) { y[k] = x[k]; });
}
void fill(const ComponentRuns& r, real v, real* y) {
  for_each_component_entry("fill (component runs)", r, kFillCost, [=](index k) { y[k] = v; });
}
void scale(const ComponentRuns& r, real a, real* y) {
  for_each_component_entry("scale (component runs)", r, kScaleCost, [=](index k) { y[k] *= a; });
}

namespace {
// cg_update, and where r_low is not null r's float copy with it
template <bool kLow>
real cg_update_in(const char* kernel, Cost cost, index n, real a, const real* p, const real* q, real* x, real* r,
                  float* r_low) {
  // one entry's update and its term of r.r (the block's tail, the device's form)
  const auto entry = [=](index i) {
    x[i] += a * p[i];
    r[i] -= a * q[i];
    if constexpr (kLow) r_low[i] = float(r[i]);
    return r[i] * r[i];
  };
  // fused in blocks so that r is still in cache (registers) when r.r is formed
  return sum_over_blocks(kernel, n, kDotBlock, cost, [=](index i0, index i1) {
    V s0{};
    index i = i0;
    for (; i + kL <= i1; i += kL) {
      store(x + i, load(x + i) + a * load(p + i));
      const V ri = load(r + i) - a * load(q + i);
      store(r + i, ri);
      if constexpr (kLow) store_float(r_low + i, ri);
      s0 += ri * ri;
    }
    real s = hsum(s0);
    for (; i < i1; ++i) s += entry(i);
    return s;
  }, entry);
}
}  // namespace

real cg_update(index n, real a, const real* p, const real* q, real* x, real* r) {
  return cg_update_in<false>("cg update", kCgUpdateCost, n, a, p, q, x, r, nullptr);
}
real cg_update(index n, real a, const real* p, const real* q, real* x, real* r, float* r_low) {
  return cg_update_in<true>("cg update (and r in float)", kCgUpdateFloatRCost, n, a, p, q, x, r, r_low);
}

namespace {
template <bool kQ, bool kLow>
real cg_start_in(index n, const real* b, const real* q, real* r, float* r_low) {
  const char* name = kQ ? (kLow ? "cg start (r = b - q, and in float)" : "cg start (r = b - q)")
                        : (kLow ? "cg start (r = b, and in float)" : "cg start (r = b)");
  const Cost cost{(kQ ? 24.0 : 16.0) + (kLow ? 4.0 : 0.0), kQ ? 3.0 : 2.0};
  const auto term = [=](index i) {  // one entry: its stores and the factors of its product
    const real ri = kQ ? b[i] - q[i] : b[i];
    r[i] = ri;
    if constexpr (kLow) r_low[i] = float(ri);
    return Factors{ri, ri};
  };
  return sum_over_blocks(name, n, kDotBlock, cost, [=](index i0, index i1) {
    return block_sum(i0, i1, [=](index i) {
      const V ri = kQ ? load(b + i) - load(q + i) : load(b + i);
      store(r + i, ri);
      if constexpr (kLow) store_float(r_low + i, ri);
      return VFactors{ri, ri};
    }, term);
  }, product_of(term));
}
}  // namespace

real cg_start(index n, const real* b, const real* q, real* r, float* r_low) {
  if (q) return r_low ? cg_start_in<true, true>(n, b, q, r, r_low) : cg_start_in<true, false>(n, b, q, r, r_low);
  return r_low ? cg_start_in<false, true>(n, b, q, r, r_low) : cg_start_in<false, false>(n, b, q, r, r_low);
}

real cg_first_direction(index n, const real* r, const float* z, real* p) {
  const auto term = [=](index i) {
    const real pi = real(z[i]);
    p[i] = pi;
    return Factors{r[i], pi};
  };
  return sum_over_blocks("cg first direction (p = z, float z)", n, kDotBlock, Cost{20, 2}, [=](index i0, index i1) {
    return block_sum(i0, i1, [=](index i) {
      const V pi = load_real(z + i);
      store(p + i, pi);
      return VFactors{load(r + i), pi};
    }, term);
  }, product_of(term));
}

real cg_update_ref(index n, real a, const real* p, const real* q, real* x, real* r) {
  for (index i = 0; i < n; ++i) {
    x[i] += a * p[i];
    r[i] -= a * q[i];
  }
  return dot_ref(n, r, r);
}

template <class T>
real jacobi_cg_update(index n, T a, const T* q, const T* dinv, T* r) {
  // the update, then its block's sum while r is in cache
  const char* name = precision_name<T>("jacobi cg update", "jacobi cg update (float)");
  return sum_over_blocks(name, n, kDotBlock, in_precision<T>(kJacobiCgUpdateCost), [=](index i0, index i1) {
#pragma omp simd
    for (index i = i0; i < i1; ++i) r[i] -= a * q[i];
    return block_dot<true>(i0, i1, r, dinv, r);
  }, [=](index i) {
    r[i] -= a * q[i];
    return real(r[i]) * (real(dinv[i]) * real(r[i]));
  });
}

template <class T>
real jacobi_cg_update_ref(index n, T a, const T* q, const T* dinv, T* r) {
  real s = 0;
  for (index i = 0; i < n; ++i) {
    r[i] -= a * q[i];
    s += real(r[i]) * (real(dinv[i]) * real(r[i]));
  }
  return s;
}

template <class T>
void jacobi_xpay(index n, const T* dinv, const T* r, T b, T* p) {
  for_each_entry(precision_name<T>("jacobi xpay", "jacobi xpay (float)"), n, in_precision<T>(kJacobiXpayCost),
                 [=](index i) { p[i] = dinv[i] * r[i] + b * p[i]; });
}

template <class To, class From>
void convert(index n, const From* x, To* y) {
  for_each_entry(precision_name<To>("convert to double", "convert to float"), n,
                 Cost{double(sizeof(From) + sizeof(To)), 0}, [=](index i) { y[i] = To(x[i]); });
}

template <class To, class From>
void scatter_to(index n, const index* at, const From* x, To* y) {
  for_each_entry("scatter", n, Cost{double(sizeof(index) + sizeof(From) + 2 * sizeof(To)), 0},
                 [=](index k) { y[at[k]] = To(x[k]); });
}

template <class To, class From>
void gather_from(index n, const index* at, const From* x, To* y) {
  for_each_entry("gather", n, Cost{double(sizeof(index) + sizeof(From) + 2 * sizeof(To)), 0},
                 [=](index k) { y[k] = To(x[at[k]]); });
}

template <class To>
void reciprocal_or_zero(index n, const real* x, To* y) {
  for_each_entry(precision_name<To>("reciprocal", "reciprocal (float)"), n, Cost{double(sizeof(real) + sizeof(To)), 1},
                 [=](index i) { y[i] = x[i] != 0 ? To(1 / x[i]) : To(0); });
}

template <class T>
void cheb_update(index n, T s, T t, const T* dinv, const T* r, const T* x, T* y) {
  const char* name = precision_name<T>("chebyshev update", "chebyshev update (float)");
  for_each_entry(name, n, in_precision<T>(kChebUpdateCost), [=](index i) {
    const T yn = x[i] + t * dinv[i] * r[i];
    y[i] = yn + s * (x[i] - y[i]);
  });
}

template <class T>
void cheb_first(index n, T t, const T* dinv, const T* b, T* x) {
  const char* name = precision_name<T>("chebyshev first", "chebyshev first (float)");
  for_each_entry(name, n, in_precision<T>(kChebFirstCost), [=](index i) { x[i] = t * dinv[i] * b[i]; });
}

template <class T>
void cheb_first_on_guess(index n, T t, const T* dinv, T* r, T* x) {
  const char* name = precision_name<T>("chebyshev first on a guess", "chebyshev first on a guess (float)");
  for_each_entry(name, n, in_precision<T>(kChebFirstOnGuessCost), [=](index i) {
    const T x0 = x[i];
    x[i] = x0 + t * dinv[i] * r[i];
    r[i] = x0;
  });
}

template real dot<double, double>(index, const double*, const double*);
template real dot<float, float>(index, const float*, const float*);
template real dot<double, float>(index, const double*, const float*);
template real dot_ref<double>(index, const double*, const double*);
template real dot_ref<float>(index, const float*, const float*);
template real jacobi_cg_update<double>(index, double, const double*, const double*, double*);
template real jacobi_cg_update<float>(index, float, const float*, const float*, float*);
template real jacobi_cg_update_ref<double>(index, double, const double*, const double*, double*);
template real jacobi_cg_update_ref<float>(index, float, const float*, const float*, float*);
template void jacobi_xpay<double>(index, const double*, const double*, double, double*);
template void jacobi_xpay<float>(index, const float*, const float*, float, float*);
template void fill<double>(index, double, double*);
template void fill<float>(index, float, float*);
template void reciprocal_or_zero<double>(index, const real*, double*);
template void reciprocal_or_zero<float>(index, const real*, float*);
template void convert<float, double>(index, const double*, float*);
template void convert<double, float>(index, const float*, double*);
template void scatter_to<double, double>(index, const index*, const double*, double*);
template void scatter_to<float, double>(index, const index*, const double*, float*);
template void gather_from<double, double>(index, const index*, const double*, double*);
template void gather_from<double, float>(index, const index*, const float*, double*);
template void cheb_update<double>(index, double, double, const double*, const double*, const double*, double*);
template void cheb_update<float>(index, float, float, const float*, const float*, const float*, float*);
template void cheb_first<double>(index, double, const double*, const double*, double*);
template void cheb_first<float>(index, float, const float*, const float*, float*);
template void cheb_first_on_guess<double>(index, double, const double*, double*, double*);
template void cheb_first_on_guess<float>(index, float, const float*, float*, float*);


}  // namespace tresca
