// The stiffness operator of one grid as a LinearOperator (see
// kernels/elasticity.hpp for what is computed and the data layout), with an
// optional block term B on the bottom face (kernels/boundary_block.hpp):
//
//   y = (K + B) x   on free dofs,   y = x on constrained dofs.
#pragma once
#include <vector>

#include "kernels/elasticity.hpp"
#include "core/solvers/operator.hpp"

namespace tresca {

class ElasticityOperator : public LinearOperator {
 public:
  ElasticityOperator() = default;
  ElasticityOperator(const GridDims& g, unsigned faces, real E, real nu);

  index size() const override { return k_.size(); }
  void apply(const real* x, real* y) const override;
  // y = (K + B) x on output planes [z_begin, z_end) only
  void apply_planes(const real* x, real* y, index z_begin, index z_end) const;
  // r = b - (K + B) x, fused into the apply (no separate vector pass)
  void residual(const real* b, const real* x, real* r) const;

  const GridDims& grid() const { return k_.g; }
  unsigned faces() const { return k_.faces; }
  const ElasticityStencil& stencil() const { return k_; }

  // B: 4 fields of nx*ny (bxx, bxy, byy, bzz); empty vector removes the term.
  // Entries on constrained nodes are ignored (set to zero).
  void set_bottom_block(std::vector<real> B);
  const std::vector<real>& bottom_block() const { return B_; }

  // diag(K + B), 1 on constrained dofs
  std::vector<real> diagonal() const;

 private:
  ElasticityStencil k_;
  std::vector<real> B_;
};

}  // namespace tresca
