// The pieces of the multigrid V-cycle (multigrid.hpp) that see only vectors:
//
// * chebyshev_smooth: `degree` steps of the Chebyshev polynomial in D^{-1}A
//   targeting [lmax/range, lmax]; `residual(x, r)` forms r = b - A x;
// * lanczos_lmax: the largest eigenvalue of D^{-1}A from 15 steps of
//   Jacobi-PCG (Lanczos), times 1.15, at least 2.3; dots through `reduce`
//   (the sum over the ranks of a split level; null: one part);
// * project_bottom_block: P^T B of a bottom-plane block, lumped per entry.
#pragma once
#include <functional>
#include <vector>

#include "kernels/launch.hpp"
#include "kernels/transfer.hpp"
#include "kernels/vector_ops.hpp"
#include "core/util/reduction.hpp"

namespace tresca {

template <class T, class Residual>
void chebyshev_smooth(index n, real lmax, real range, int degree, bool zero_guess, const T* dinv, const T* b, T* x, T* r,
                      T* d, Residual&& residual) {
  const real lmin = lmax / range;
  const real theta = (lmax + lmin) / 2, delta = (lmax - lmin) / 2, sigma = theta / delta;
  if (zero_guess) {
    cheb_first<T>(n, T(1 / theta), dinv, b, d, x);
  } else {
    residual(x, r);
    cheb_first<T>(n, T(1 / theta), dinv, r, d, x, false);
  }
  real rho = 1 / sigma;
  for (int k = 1; k < degree; ++k) {
    residual(x, r);
    const real rho_new = 1 / (2 * sigma - rho);
    cheb_update<T>(n, T(rho_new * rho), T(2 * rho_new / delta), dinv, r, d, x);
    rho = rho_new;
  }
}

// r: the start vector (overwritten); apply(p, q): q = A p (p is the
// estimate's own vector: apply may update its ghost entries)
real lanczos_lmax(index n, const std::function<void(real*, real*)>& apply, const Field<real>& dinv,
                  Field<real> r, const Reduction* reduce = nullptr);

// the coarse bottom block P^T B of the fine one (4 fields of nx*ny each;
// host data, t wherever it lives)
std::vector<real> project_bottom_block(const Transfer& t, const std::vector<real>& fine);

}  // namespace tresca
