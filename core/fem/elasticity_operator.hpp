// The stiffness operator K of a grid, or of one rank's slab of it, as a
// LinearOperator (kernels/elasticity.hpp: what is computed and the data
// layout), with an optional block term B on the bottom face
// (kernels/boundary_block.hpp):
//
//   y = (K + B) x   on free dofs,   y = x on constrained dofs.
//
// One operator for one rank and many: its vectors live on a slab's local
// box (core/parallel/slab.hpp), the owned node rows and one ghost row per
// neighbouring rank. apply and residual write the owned rows, zero the
// ghost rows, and read x's ghost rows as they are; update_ghosts(x) makes
// them current (the halo exchange, core/parallel/halo.hpp). The whole grid
// is the slab of one rank: no ghost rows, nothing sent, the same kernels.
// Sums over a vector's entries count every global entry once (ghost rows
// of outputs are 0), so dots need only the ranks' sum.
//
// Precision: double, and single for the multigrid V-cycle's levels (the
// coefficients and B rounded to float; messages of floats).
#pragma once
#include <vector>

#include "core/parallel/halo.hpp"
#include "core/parallel/slab.hpp"
#include "core/solvers/operator.hpp"
#include "kernels/elasticity.hpp"
#include "kernels/launch.hpp"

namespace tresca {

class ElasticityOperator : public LinearOperator {
 public:
  ElasticityOperator() = default;
  // the whole grid g with constrained faces
  ElasticityOperator(const GridDims& g, unsigned faces, real E, real nu);
  // rank's slab s of the grid s.global, whose constrained faces are `faces`
  ElasticityOperator(const Slab& s, unsigned faces, real E, real nu);

  index size() const override { return 3 * slab_.local.nodes(); }
  void apply(const real* x, real* y) const override { apply_rows<real>(x, operator_out(y), 0, slab_.local.nz()); }
  void apply(const float* x, float* y) const { apply_rows<float>(x, operator_out(y), 0, slab_.local.nz()); }
  // y = (K + B) x on output planes [z_begin, z_end) of the owned rows;
  // other entries of y untouched
  void apply_planes(const real* x, real* y, index z_begin, index z_end) const;
  // r = b - (K + B) x, fused into the apply (no separate vector pass)
  template <class T>
  void residual(const T* b, const T* x, T* r) const {
    apply_rows<T>(x, residual_out(b, r), 0, slab_.local.nz());
  }
  // a step of the multigrid smoother's Chebyshev iteration fused into the
  // apply (kernels/apply_out.hpp): with r = b - (K + B) x never stored,
  // y = x + s (x - y) + t dinv r, y holding the iterate before x (not read
  // where from_zero says that one is zero, or s == 0); x's ghost rows as
  // they are, y's zeroed. dinv: this operator's 1 / diag (K + B), read on
  // the bottom plane only; elsewhere the stencil's own weights are used,
  // which it must equal (apply_out.hpp)
  template <class T>
  void chebyshev_step(const T* b, const T* x, T* y, const T* dinv, T s, T t, bool from_zero = false) const {
    apply_rows<T>(x, chebyshev_out(b, dinv, s, t, y, from_zero), 0, slab_.local.nz());
  }
  void update_ghosts(real* x) const override { halo_.exchange(x); }
  void update_ghosts(float* x) const { halo_.exchange(x); }
  template <class T>
  void zero_ghosts(T* v) const {
    halo_.zero_ghosts(v);
  }

  // the local box of the vectors (the whole grid on one rank)
  const GridDims& grid() const { return slab_.local; }
  const Slab& slab() const { return slab_; }
  bool distributed() const { return !halo_.empty(); }
  // constrained faces of the local box, and of the global grid
  unsigned faces() const { return k_.faces; }
  unsigned global_faces() const { return global_faces_; }
  const ElasticityStencil& stencil() const { return k_; }
  const HaloCounts& halo_counts() const { return halo_.counts(); }

  // B over the whole bottom plane of the global grid: 4 fields of nx*ny
  // (bxx, bxy, byy, bzz), host data; the operator keeps its owned rows,
  // where its launches run. Entries on
  // constrained nodes are ignored (set to zero); empty removes the term.
  void set_bottom_block(const std::vector<real>& B);
  // B on the local box's bottom plane (ghost rows 0); empty: none
  const Field<real>& bottom_block() const { return B_; }

  // diag(K + B) on the owned rows, 1 on constrained dofs, 0 on ghost rows
  Field<real> diagonal() const;

 private:
  template <class T>
  const ElasticityStencilT<T>& stencil_in() const;
  template <class T>
  const Field<T>& block_in() const;
  // an apply of K + B to x, written as `out` says (kernels/apply_out.hpp), on
  // planes [z_begin, z_end) of the owned rows
  template <class T>
  void apply_rows(const T* x, const ApplyOut<T>& out, index z_begin, index z_end) const;

  Slab slab_;
  unsigned global_faces_ = 0;
  Halo halo_;
  ElasticityStencil k_;
  ElasticityStencilT<float> kf_;
  Field<real> B_;
  Field<float> Bf_;
};

// B (4 fields over the bottom plane of grid g) := 0 on the nodes of the
// constrained faces; empty: nothing
void zero_constrained_bottom_block(const GridDims& g, unsigned faces, std::vector<real>& B);

// z = D^{-1} r with D = diag(K + B) (Jacobi; 0 on ghost rows): a simple CG
// preconditioner (the elastic driver's --pc jacobi, tests)
class JacobiPreconditioner : public LinearOperator {
 public:
  explicit JacobiPreconditioner(const ElasticityOperator& K);
  index size() const override { return index(inv_.size()); }
  void apply(const real* r, real* z) const override;

 private:
  Field<real> inv_;
};

}  // namespace tresca
