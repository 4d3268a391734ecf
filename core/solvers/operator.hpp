// What a solver sees: a square linear operator y = A x on vectors of size().
// (MFEM Operator::Mult, Ginkgo LinOp.) Preconditioners are operators too.
#pragma once
#include "kernels/types.hpp"

namespace tresca {

class LinearOperator {
 public:
  virtual ~LinearOperator() = default;
  virtual index size() const = 0;
  virtual void apply(const real* x, real* y) const = 0;
};

}  // namespace tresca
