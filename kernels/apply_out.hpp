// What an apply of the elasticity operator writes for each of its entries.
//
// Every form of the apply (the banded CPU apply of each instruction set, the
// device's row form, the bottom block's term on the contact face) computes
// v = ((K [+ B]) x)_j for its entries j = a N + n, and hands v to put(); so
// the same sweep gives one of
//
//   the operator   y_j = v                                  operator_out(y)
//   the residual   y_j = b_j - v                            residual_out(b, y)
//   a Chebyshev    r_j = b_j - v (never stored),            chebyshev_out(b, dinv, d, s, t, y)
//   step           d_j = s d_j + t dinv_j r_j,
//                  y_j = x_j + d_j
//
// The last is the multigrid smoother's step fused into the apply
// (core/multigrid/smoothing.hpp): one sweep reads x, b, dinv and d and
// writes d and the new iterate y (x != y), where the residual and a separate
// update would write r and read it back, and read and write x once more:
// 7 streams instead of 10 (RESULTS.md §0p). Where s == 0 (the first step)
// d is not read, so it may hold anything.
//
// U is T or a vector of T (simd.hpp): put() and add() load and store U at
// p + j, so the CPU's explicit vectors and the device's scalar lanes share
// this one definition.
#pragma once
#include "types.hpp"

namespace tresca {

template <class T>
struct ApplyOut {
  T* y = nullptr;
  const T* b = nullptr;     // the residual's and the step's right-hand side
  const T* dinv = nullptr;  // the step's; set with d, s and t
  T* d = nullptr;
  T s = 0, t = 0;
};

template <class T>
ApplyOut<T> operator_out(T* y) {
  return {y};
}
template <class T>
ApplyOut<T> residual_out(const T* b, T* y) {
  return {y, b};
}
template <class T>
ApplyOut<T> chebyshev_out(const T* b, const T* dinv, T* d, T s, T t, T* y) {
  return {y, b, dinv, d, s, t};
}

// Everything that computes with an ApplyOut has internal linkage (an unnamed
// namespace, as in stencil_row.hpp): the instruction-set variants compile
// put() with their own vectors, and the linker must never hand such a copy
// to the baseline's callers (kernels/isa.hpp).
namespace {

template <class U, class T>
inline U load_as(const T* p) {
  return *reinterpret_cast<const U*>(p);
}
template <class U, class T>
inline void store_as(T* p, U v) {
  *reinterpret_cast<U*>(p) = v;
}

// entry j's value v of an apply of x
template <class T, class U>
inline void put(const ApplyOut<T>& o, const T* x, index j, U v) {
  if (!o.dinv) {
    store_as<U>(o.y + j, o.b ? load_as<U>(o.b + j) - v : v);
    return;
  }
  U dn = o.t * load_as<U>(o.dinv + j) * (load_as<U>(o.b + j) - v);
  if (o.s != 0) dn += o.s * load_as<U>(o.d + j);
  store_as<U>(o.d + j, dn);
  store_as<U>(o.y + j, load_as<U>(x + j) + dn);
}

// entry j as if put() had been given v + w (the bottom block's term, added
// after the stencil's)
template <class T, class U>
inline void add(const ApplyOut<T>& o, index j, U w) {
  if (!o.dinv) {
    store_as<U>(o.y + j, o.b ? load_as<U>(o.y + j) - w : load_as<U>(o.y + j) + w);
    return;
  }
  const U c = o.t * load_as<U>(o.dinv + j) * w;
  store_as<U>(o.d + j, load_as<U>(o.d + j) - c);
  store_as<U>(o.y + j, load_as<U>(o.y + j) - c);
}

}  // namespace

}  // namespace tresca
