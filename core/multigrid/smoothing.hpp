// The pieces of the multigrid V-cycle (multigrid.hpp) that see only vectors:
//
// * chebyshev_smooth: `degree` steps of the Chebyshev polynomial in D^{-1}A
//   targeting [lmax/range, lmax], in the three-term form x_{k+1} = x_k +
//   s_k (x_k - x_{k-1}) + t_k Dinv (b - A x_k). `step(x, y, s, t, from_zero)`
//   is one step from x into y != x, y holding x_{k-1}, or not read where
//   from_zero says x_{k-1} = 0 (or s = 0, the first), with the residual never
//   stored (the operator's chebyshev_step: kernels/apply_out.hpp); the steps
//   go back and forth between x and r, and the iterate leaves in x. It
//   enters as 0 (zero_guess; the first step needs no residual, x = t Dinv b,
//   and goes to whichever vector makes the rest end in x; the second is
//   from_zero) or in `in` (x or r): in
//   chebyshev_entry(degree, x, r) every step is a fused one; in the other
//   vector the first step forms a residual in the free vector (`residual(x,
//   y)`, y = b - A x), updates the iterate in place and leaves x_0 where
//   the residual was (cheb_first_on_guess).
// * lanczos_lmax: the largest eigenvalue of D^{-1}A from 15 steps of
//   Jacobi-PCG (Lanczos) in double or float, times 1.15, at least 2.3;
//   dots through `reduce` (the sum over the ranks of a split level; null:
//   one part);
// * project_bottom_block: P^T B of a bottom-plane block, lumped per entry.
#pragma once
#include <functional>
#include <vector>

#include "kernels/launch.hpp"
#include "kernels/transfer.hpp"
#include "kernels/vector_ops.hpp"
#include "core/util/reduction.hpp"

namespace tresca {

// where a nonzero iterate should enter chebyshev_smooth so that every step
// is fused (the steps alternate between x and r and end in x)
template <class T>
T* chebyshev_entry(int degree, T* x, T* r) {
  return degree % 2 == 0 ? x : r;
}

template <class T, class Residual, class Step>
void chebyshev_smooth(index n, real lmax, real range, int degree, bool zero_guess, const T* dinv, const T* b, T* x, T* r,
                      Residual&& residual, Step&& step, const T* in = nullptr) {
  TRESCA_ASSERT(degree >= 1);
  const real lmin = lmax / range;
  const real theta = (lmax + lmin) / 2, delta = (lmax - lmin) / 2, sigma = theta / delta;
  // step k's coefficients: x_{k+1} = x_k + s (x_k - x_{k-1}) + t Dinv r (s = 0 for the first, k = 0)
  real rho = 1 / sigma, s = 0, t = 1 / theta;
  auto next = [&] {
    const real rho_new = 1 / (2 * sigma - rho);
    s = rho_new * rho;
    t = 2 * rho_new / delta;
    rho = rho_new;
  };
  auto other = [&](T* v) { return v == x ? r : x; };
  // where the iterate is: from a zero guess, where the first step puts it
  T* at = zero_guess ? chebyshev_entry(degree - 1, x, r) : in == r ? r : x;
  int k = 0;
  if (zero_guess) {  // from x = 0: no residual to form
    cheb_first<T>(n, T(t), dinv, b, at);
    next();
    k = 1;
  } else if (at != chebyshev_entry(degree, x, r)) {  // the first step in place
    residual(at, other(at));
    cheb_first_on_guess<T>(n, T(t), dinv, other(at), at);
    next();
    k = 1;
  }
  for (; k < degree; ++k) {
    step(at, other(at), T(s), T(t), zero_guess && k == 1);
    at = other(at);
    next();
  }
}

// r: the start vector (overwritten); apply(p, q): q = A p (p is the
// estimate's own vector: apply may update its ghost entries). T = double,
// float: the vectors and the steps' coefficients in T, the sums in double
// (the smoother's own operator and precision: Multigrid runs it in the
// V-cycle's)
template <class T>
real lanczos_lmax(index n, const std::function<void(T*, T*)>& apply, const Field<T>& dinv, Field<T> r,
                  const Reduction* reduce = nullptr);

// the coarse bottom block P^T B of the fine one (4 fields of nx*ny each;
// host data, t's lists on the host: GridHierarchy::Link::whole)
std::vector<real> project_bottom_block(const Transfer& t, const std::vector<real>& fine);

}  // namespace tresca
