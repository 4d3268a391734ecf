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

// Jacobi weights for the smoother's fused step (kernels/apply_out.hpp): 1 / d
// (d: the operator's diagonal, 1 on constrained nodes) where the step takes
// them from the stencil, and other values (1 + |random|) where it reads them
// from the array, on the bottom plane's free nodes: a test then sees which
// it used
inline std::vector<real> step_weights(const GridDims& g, unsigned faces, const std::vector<real>& d,
                                      std::uint64_t seed) {
  std::vector<real> w = random_vector(index(d.size()), seed);
  const index N = g.nodes();
  for (index iz = 0; iz < g.nz(); ++iz)
    for (index iy = 0; iy < g.ny(); ++iy)
      for (index ix = 0; ix < g.nx(); ++ix)
        for (int a = 0; a < 3; ++a) {
          const index j = a * N + g.node(ix, iy, iz);
          w[j] = iz == 0 && !node_constrained(g, faces, ix, iy, iz) ? 1 + std::abs(w[j]) : 1 / d[j];
        }
  return w;
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
