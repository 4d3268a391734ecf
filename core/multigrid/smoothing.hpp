// The pieces of the multigrid V-cycle (multigrid.hpp) that see only vectors:
//
// * chebyshev_smooth: `degree` steps of the Chebyshev polynomial in D^{-1}A
//   targeting [lmax/range, lmax]: x_{k+1} = x_k + d_{k+1} with
//   d_{k+1} = s_k d_k + t_k Dinv (b - A x_k). `step(x, y, s, t)` is one step
//   from x into y != x with the residual never stored (the operator's
//   chebyshev_step: kernels/apply_out.hpp); the steps run in pairs x -> r ->
//   x, so r serves as the second iterate; a step left over (an even degree,
//   or the first step of a nonzero guess with an odd one) forms
//   `residual(x, r)`, r = b - A x, and updates x in place. From a zero
//   guess the first step needs no residual (x = d = t Dinv b).
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

template <class T, class Residual, class Step>
void chebyshev_smooth(index n, real lmax, real range, int degree, bool zero_guess, const T* dinv, const T* b, T* x, T* r,
                      T* d, Residual&& residual, Step&& step) {
  const real lmin = lmax / range;
  const real theta = (lmax + lmin) / 2, delta = (lmax - lmin) / 2, sigma = theta / delta;
  // step k's coefficients: d = s d + t Dinv r (s = 0 for the first, k = 0)
  real rho = 1 / sigma, s = 0, t = 1 / theta;
  auto next = [&] {
    const real rho_new = 1 / (2 * sigma - rho);
    s = rho_new * rho;
    t = 2 * rho_new / delta;
    rho = rho_new;
  };
  int k = 0;
  if (zero_guess) {  // from x = 0: no residual to form
    cheb_first<T>(n, T(t), dinv, b, d, x);
    next();
    k = 1;
  }
  if ((degree - k) % 2 == 1) {  // the odd step out, in place
    residual(x, r);
    if (k == 0)
      cheb_first<T>(n, T(t), dinv, r, d, x, false);
    else
      cheb_update<T>(n, T(s), T(t), dinv, r, d, x);
    next();
    ++k;
  }
  for (; k < degree; k += 2) {  // the rest fused in pairs, x -> r -> x: the iterate ends in x
    step(x, r, T(s), T(t));
    next();
    step(r, x, T(s), T(t));
    next();
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
