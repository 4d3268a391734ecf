// Small helpers shared by the tests: deterministic random vectors and norms.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "kernels/grid.hpp"
#include "kernels/isa.hpp"
#include "kernels/launch.hpp"
#include "kernels/types.hpp"

namespace tresca::test {

// the seed prism's box (2 x 1 x 0.9) with ex x ey x ez bricks
inline GridDims prism(index ex, index ey, index ez) {
  GridDims g;
  g.ex = ex;
  g.ey = ey;
  g.ez = ez;
  g.lx = 2;
  g.ly = 1;
  g.lz = 0.9;
  return g;
}

// the launches of `kernel` that ran where `ran` says, in a census by kernel
// (launches_by_kernel); none (0 calls) where it has no such row
inline KernelLaunches launches_of(const std::vector<KernelLaunches>& all, const std::string& kernel, Ran ran) {
  for (const KernelLaunches& k : all)
    if (k.kernel == kernel && k.ran == ran) return k;
  return KernelLaunches{kernel, ran};
}

inline std::vector<real> random_vector(index n, std::uint64_t seed = 1) {
  std::vector<real> v(n);
  std::uint64_t s = seed * 0x9E3779B97F4A7C15ULL + 7;
  for (auto& x : v) {
    s ^= s << 13;
    s ^= s >> 7;
    s ^= s << 17;
    x = real(s >> 11) / real(1ULL << 53) * 2 - 1;
  }
  return v;
}

// for std::vector and Field alike
template <class Vec>
real max_abs(const Vec& v) {
  real m = 0;
  for (real x : v) m = std::max(m, std::abs(x));
  return m;
}

template <class VecA, class VecB>
real max_abs_diff(const VecA& a, const VecB& b) {
  real m = 0;
  for (size_t i = 0; i < a.size(); ++i) m = std::max(m, std::abs(a[i] - b[i]));
  return m;
}

// f() once with each instruction-set variant this program holds and this
// processor runs (kernels/isa.hpp), the failures traced to the variant; the
// variant in use before it after it
template <class F>
void for_each_isa(F&& f) {
  const IsaKernels& before = isa();
  for (const IsaKernels* v : isa_variants()) {
    SCOPED_TRACE(std::string("instruction set ") + v->name + " (" + v->id + " variant)");
    set_isa(*v);
    f(*v);
  }
  set_isa(before);
}

}  // namespace tresca::test
