// What an apply of the elasticity operator writes for each of its entries.
//
// Every form of the apply (the banded CPU apply of each instruction set, the
// device's row form, the bottom block's term on the contact face) computes
// v = ((K [+ B]) x)_j for its entries j = a N + n, and hands v to put(); so
// the same sweep gives one of
//
//   the operator   y_j = v                                  operator_out(y)
//   the residual   y_j = b_j - v                            residual_out(b, y)
//   a Chebyshev    r_j = b_j - v (never stored),            chebyshev_out(b, dinv, s, t, y)
//   step           y_j = x_j + s (x_j - y_j) + t dinv_j r_j
//   ... from zero  y_j = x_j + s x_j + t dinv_j r_j          chebyshev_out(b, dinv, s, t, y, true)
//
// The last is the multigrid smoother's step fused into the apply
// (core/multigrid/smoothing.hpp) in the three-term form of the Chebyshev
// recurrence: y holds the iterate before x and is overwritten by the one
// after it, entry by entry. Its Jacobi weights dinv = 1 / diag(K + B) are
// read from the array only on the bottom plane (iz = 0, where a bottom block
// may add to the diagonal); elsewhere they are the stencil's own inv_center
// of the node's class (elasticity.hpp), and 1 on constrained nodes (their
// rows are the identity's), which the array must equal there (the
// multigrid's is made from the same stencil).
// So one sweep streams x, b and y and writes y, where the residual and a
// separate update would write r and read it back, and read and write x
// once more; and where the two-term form (d = s d + t dinv r, y = x + d)
// with dinv as an array streamed dinv and d as well: 4 streams instead of
// 7 (RESULTS.md §0zn) and of 10 (§0p). Where the iterate before x is zero
// (the second step from a zero guess) or s == 0 (a first step), y is not
// read, so it may hold anything: 3 streams, and the step before need not
// have written zeros into y.
//
// U is T or a vector of T (simd.hpp): put(), put_lanes() and add() load and
// store U at p + j, so the CPU's explicit vectors and the device's scalar
// lanes share this one definition.
#pragma once
#include <type_traits>

#include "types.hpp"

namespace tresca {

template <class T>
struct ApplyOut {
  T* y = nullptr;
  const T* b = nullptr;     // the residual's and the step's right-hand side
  const T* dinv = nullptr;  // the step's (read where the header says); set with s and t
  T s = 0, t = 0;
  // the step's iterate before x is zero: y not read (0 or 1, a whole word:
  // the struct has no padding, whose stale bytes the device guard would
  // read as host addresses in a device body, kernels/launch.hpp)
  index prev_zero = 0;
};

static_assert(sizeof(ApplyOut<float>) == 3 * sizeof(void*) + 2 * sizeof(float) + sizeof(index) &&
                  sizeof(ApplyOut<double>) == 3 * sizeof(void*) + 2 * sizeof(double) + sizeof(index),
              "ApplyOut without padding (prev_zero's comment)");

template <class T>
ApplyOut<T> operator_out(T* y) {
  return {y};
}
template <class T>
ApplyOut<T> residual_out(const T* b, T* y) {
  return {y, b};
}
template <class T>
ApplyOut<T> chebyshev_out(const T* b, const T* dinv, T s, T t, T* y, bool prev_zero = false) {
  return {y, b, dinv, s, t, prev_zero ? 1 : 0};
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

// The four things put() can do, known when the kernel is compiled: each
// apply dispatches once on kind(out), so its inner loops carry no branch on
// it (with_kind). step_from_zero: a step that does not read y (the iterate
// before x zero, or s == 0).
enum class OutKind { value, residual, step_from_zero, step };
template <class T>
constexpr OutKind kind(const ApplyOut<T>& o) {
  return o.dinv ? (o.s != 0 && o.prev_zero == 0 ? OutKind::step : OutKind::step_from_zero)
                : o.b ? OutKind::residual
                      : OutKind::value;
}
template <OutKind K>
using Kind = std::integral_constant<OutKind, K>;
// f(Kind<kind(o)>{})
template <class T, class F>
inline void with_kind(const ApplyOut<T>& o, const F& f) {
  switch (kind(o)) {
    case OutKind::value: return f(Kind<OutKind::value>{});
    case OutKind::residual: return f(Kind<OutKind::residual>{});
    case OutKind::step_from_zero: return f(Kind<OutKind::step_from_zero>{});
    case OutKind::step: return f(Kind<OutKind::step>{});
  }
}

constexpr bool is_step(OutKind k) { return k == OutKind::step_from_zero || k == OutKind::step; }

// The step's dinv_j for entry j of component a of a run of free nodes: the
// run's class's weights (dc: the stencil's inv_center of that class, its 3
// components) or, where dc is null (the bottom plane), o.dinv's. Nothing
// for the other kinds.
template <OutKind K, class U, class T>
inline U dinv_at(const ApplyOut<T>& o, const T* dc, int a, index j) {
  if constexpr (!is_step(K))
    return U{};
  else
    return dc ? U{} + dc[a] : load_as<U>(o.dinv + j);
}

// entry j's value v of an apply of x (K = kind(o); o by value: its
// pointers stay in registers across the stores); dj: dinv_at's for j
template <OutKind K, class T, class U>
inline void put(const ApplyOut<T> o, const T* x, index j, U v, U dj) {
  if constexpr (K == OutKind::value) {
    store_as<U>(o.y + j, v);
  } else if constexpr (K == OutKind::residual) {
    store_as<U>(o.y + j, load_as<U>(o.b + j) - v);
  } else {
    const U xj = load_as<U>(x + j);
    const U yn = xj + o.t * dj * (load_as<U>(o.b + j) - v);
    // (s (x - 0) is s x bit for bit; s == 0 adds a zero)
    store_as<U>(o.y + j, yn + o.s * (K == OutKind::step ? xj - load_as<U>(o.y + j) : xj));
  }
}

// The same for a vector U whose lanes where `keep` is true were put before
// (the banded apply's overlapping last vector of a run): those lanes of y
// are stored back as they are, so each entry is put once.
template <OutKind K, class T, class U, class Mask>
inline void put_lanes(const ApplyOut<T> o, const T* x, index j, U v, U dj, Mask keep) {
  const U y_was = load_as<U>(o.y + j);
  put<K>(o, x, j, v, dj);
  store_as<U>(o.y + j, keep ? y_was : load_as<U>(o.y + j));
}

// entry j as if put() had been given v + w (the bottom block's term, added
// after the stencil's: on the bottom plane, so dinv from the array)
template <OutKind K, class T, class U>
inline void add(const ApplyOut<T> o, index j, U w) {
  if constexpr (K == OutKind::value) {
    store_as<U>(o.y + j, load_as<U>(o.y + j) + w);
  } else if constexpr (K == OutKind::residual) {
    store_as<U>(o.y + j, load_as<U>(o.y + j) - w);
  } else {
    store_as<U>(o.y + j, load_as<U>(o.y + j) - o.t * load_as<U>(o.dinv + j) * w);
  }
}

}  // namespace

// Cost per node of a Chebyshev step beyond the residual's: reads y's
// previous values (3 dofs, double; dinv is the class's, in cache), 6 flops a
// dof; from zero, the flops only
constexpr Cost kChebStepExtraCost{24, 18}, kChebStepFromZeroExtraCost{0, 18};

}  // namespace tresca
