// What a solver sees: a square linear operator y = A x on vectors of size().
// (MFEM Operator::Mult, Ginkgo LinOp.) Preconditioners are operators too.
//
// Ghost entries: an operator on a part of a distributed grid (a rank's
// slab, core/fem/elasticity_operator.hpp) reads, besides the entries its
// part owns, copies of a few of its neighbours' (ghost entries). apply()
// reads them as they are; update_ghosts(x) makes them current (the halo
// exchange, HPCG's ExchangeHalo), writing x's ghost entries and nothing
// else. A solver calls it on its own vector before each apply; operators
// without ghosts do nothing.
#pragma once
#include <stdexcept>

#include "kernels/types.hpp"

namespace tresca {

class LinearOperator {
 public:
  virtual ~LinearOperator() = default;
  virtual index size() const = 0;
  virtual void apply(const real* x, real* y) const = 0;
  virtual void update_ghosts(real* x) const { (void)x; }
  // An operator that computes in single precision (the multigrid's float
  // V-cycle) also takes and gives float vectors: apply() converts x in and
  // y out in sweeps of their own, which a solver that keeps the float
  // copies itself (pcg: r's written by its update, z's read where it is
  // used) saves. apply_in_float(x, y) is apply() without the conversions:
  // the same y, rounded to float.
  virtual bool works_in_float() const { return false; }
  virtual void apply_in_float(const float* x, float* y) const {
    (void)x, (void)y;
    throw std::logic_error("apply_in_float: this operator works in double precision");
  }
};

// An operator y = A x whose evaluation also yields s = B x for a second linear
// map B (size side_size()) at no extra cost, e.g. A = mask(S + H) yields S x.
// CG (cg.hpp) then returns B x of its solution as well, accumulated from the
// products of its own iterations (no extra application of B).
class LinearOperatorWithSide : public LinearOperator {
 public:
  virtual index side_size() const = 0;
  virtual void apply(const real* x, real* y, real* s) const = 0;
  using LinearOperator::apply;
};

}  // namespace tresca
