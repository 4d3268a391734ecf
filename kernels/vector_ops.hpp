// Vector kernels used by the Krylov solvers and smoothers (length n, OpenMP).
//
// dot/norm are deterministic: the sum is taken over fixed blocks of
// kDotBlock entries and the block sums are added serially, so results are
// bitwise identical for any thread count.
//
// Cost models (bytes moved, flops), n entries of 8 bytes:
//   dot 16n B, 2n F;  axpy 24n B, 2n F;  xpay 24n B, 2n F;  triad 24n B, 2n F;
//   cg_update (x += a p, r -= a q, returns r.r) 48n B, 6n F;
//   (the CG's float copies: dot of double and float 12n B, xpay from a
//   float x 20n B, cg_update writing r in float too 52n B)
//   cheb_update (y = x + t Dinv r + s (x - y)) 40n B, 6n F;
//   cheb_first (x = t Dinv b) 24n B, 2n F;
//   cheb_first_on_guess ((x, r) = (x + t Dinv r, x)) 40n B, 3n F;
//   jacobi_cg_update (r -= a q, returns r.(Dinv r)) 32n B, 5n F;
//   jacobi_xpay (p = Dinv r + b p) 32n B, 3n F.
// (Fields of float move half the bytes: in_precision<float>, types.hpp.
// Sums are taken in double for float vectors too.)
#pragma once
#include "types.hpp"

namespace tresca {

constexpr index kDotBlock = 4096;
// per entry (the table above)
constexpr Cost kDotCost{16, 2}, kAxpyCost{24, 2}, kXpayCost{24, 2}, kCgUpdateCost{48, 6}, kChebUpdateCost{40, 6},
    kChebFirstCost{24, 2}, kChebFirstOnGuessCost{40, 3}, kCopyCost{16, 0}, kFillCost{8, 0}, kScaleCost{16, 1},
    kHadamardCost{24, 1}, kTriadCost{24, 2}, kJacobiCgUpdateCost{32, 5}, kJacobiXpayCost{32, 3};
// the CG's forms with a float vector (the table's note)
constexpr Cost kDotFloatYCost{12, 2}, kXpayFloatXCost{20, 2}, kCgUpdateFloatRCost{52, 6};

template <class TX, class TY>
real dot(index n, const TX* x, const TY* y);  // (TX, TY) = (double, double), (float, float), (double, float)
template <class T>
real dot_ref(index n, const T* x, const T* y);
real norm2(index n, const real* x);
void axpy(index n, real a, const real* x, real* y);        // y += a x
void xpay(index n, const real* x, real a, real* y);        // y = x + a y
void xpay(index n, const float* x, real a, real* y);       // the same with x widened: 20n B
void copy(index n, const real* x, real* y);                // y = x
template <class T>
void fill(index n, T v, T* y);                             // y = v (T = double, float)
template <class To, class From>
void convert(index n, const From* x, To* y);               // y = To(x) (double <-> float)
void scale(index n, real a, real* y);                      // y *= a
void hadamard(index n, const real* d, const real* x, real* y);  // y = d .* x
void triad(index n, const real* b, real s, const real* c, real* a);  // a = b + s c (STREAM's triad)
// The same on the three component blocks of a vector of N nodes (layout
// c N + node), entries [first, first + count) of each, in one launch: a
// plane of a 3D vector (core/contact/steklov.cpp), a launch where three
// were (on a GPU each costs about as much as a plane's work)
struct ComponentRuns {
  index N, first, count;
};
void axpy(const ComponentRuns& r, real a, const real* x, real* y);
void copy(const ComponentRuns& r, const real* x, real* y);
void fill(const ComponentRuns& r, real v, real* y);
void scale(const ComponentRuns& r, real a, real* y);
// a short vector's entries placed into, and taken from, entries of a long
// one: y[at[k]] = To(x[k]) (scatter_to), y[k] = To(x[at[k]]) (gather_from),
// k < n (To, From: double, float)
template <class To, class From>
void scatter_to(index n, const index* at, const From* x, To* y);
template <class To, class From>
void gather_from(index n, const index* at, const From* x, To* y);
// y = 1 / x where x != 0, else 0 (Jacobi's inverse diagonal; To = double, float)
template <class To>
void reciprocal_or_zero(index n, const real* x, To* y);
// x += a p; r -= a q; returns r.r
real cg_update(index n, real a, const real* p, const real* q, real* x, real* r);
// the same, and r_low = float(r) (a single-precision preconditioner's
// input): 52n B
real cg_update(index n, real a, const real* p, const real* q, real* x, real* r, float* r_low);
// CG's start: r = b - q (b where q is null) and, where r_low is not null,
// r_low = float(r); returns r.r, the bits of dot(n, r, r): 16n-28n B
real cg_start(index n, const real* b, const real* q, real* r, float* r_low);
// CG's first direction from a preconditioner's float z: p = z (widened);
// returns r.p, the bits of dot(n, r, p): 20n B
real cg_first_direction(index n, const real* r, const float* z, real* p);
real cg_update_ref(index n, real a, const real* p, const real* q, real* x, real* r);
// Jacobi-preconditioned CG without its iterate (the Lanczos estimate of
// the smoother's lmax, core/multigrid/smoothing.hpp; T = double, float):
// r -= a q, returning r.(dinv .* r); and p = dinv .* r + b p
template <class T>
real jacobi_cg_update(index n, T a, const T* q, const T* dinv, T* r);
template <class T>
real jacobi_cg_update_ref(index n, T a, const T* q, const T* dinv, T* r);
template <class T>
void jacobi_xpay(index n, const T* dinv, const T* r, T b, T* p);
// The Chebyshev smoother's steps outside the apply (core/multigrid/smoothing.hpp:
// x_{k+1} = x_k + s (x_k - x_{k-1}) + t Dinv r_k), T = double, float.
//
// y = x + t dinv .* r + s (x - y), y holding x_{k-1} on entry: a step's
// update unfused from its residual (the V-cycle runs the fused step of the
// apply, apply_out.hpp, with the same arithmetic in the same order; this is
// bench_kernels' ChebStepUnfused reference)
template <class T>
void cheb_update(index n, T s, T t, const T* dinv, const T* r, const T* x, T* y);
// the first step from x_0 = 0: x = t dinv .* b (the next step is told
// that x_0 = 0: chebyshev_out's prev_zero)
template <class T>
void cheb_first(index n, T t, const T* dinv, const T* b, T* x);
// the first step from a guess x with r = b - A x: x += t dinv .* r (as
// cheb_update with s = 0, bit for bit), and r = the guess, x_0 for the next
template <class T>
void cheb_first_on_guess(index n, T t, const T* dinv, T* r, T* x);

}  // namespace tresca
