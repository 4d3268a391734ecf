// Geometric multigrid V-cycle for the Q1 elasticity operator on the brick grid,
// used as a preconditioner (one V-cycle with zero initial guess per apply).
//
// Hierarchy: each coarser grid has ceil(e/2) elements along every axis whose
// spacing is within 1.5x of the finest (semi-coarsening for anisotropic
// bricks; all axes on the benchmark's near-cubic bricks), non-nested when e is
// odd, the same box and constrained faces, and is rediscretised (same brick
// formula, coarse h). Transfers are trilinear interpolation and
// its exact transpose (kernels/transfer.hpp). Coarsening stops when a grid has
// at most `coarse_nodes` nodes; that grid is solved directly (Eigen sparse
// LDLT of the assembled matrix, factorised once).
//
// Smoother: Chebyshev polynomial of degree `degree` in D^{-1}A (Jacobi),
// targeting [lmax/range, lmax]; lmax from 15 steps of Jacobi-PCG (Lanczos),
// times 1.15. The same polynomial pre and post keeps the V-cycle symmetric,
// so it is a valid CG preconditioner.
//
// Optional bottom-face block B (elasticity_operator.hpp): coarse levels get
// the lumped Galerkin projection B_c = P^T B_f (restricted per entry), which
// preserves row sums of P^T B P. The coarse factorisation is redone.
//
// Cost per V-cycle on a level with n dofs: (2*degree) applies of A, plus
// residual apply, one restriction and one prolongation: about
// (2*degree+1) * 306/3 + 20 flops per dof; the hierarchy adds about 1/7.
#pragma once
#include <Eigen/SparseCholesky>
#include <memory>
#include <string>
#include <vector>

#include "../kernels/transfer.hpp"
#include "assembly.hpp"
#include "elasticity_operator.hpp"

namespace tresca {

struct MGOptions {
  int degree = 3;
  real range = 15;
  index coarse_nodes = 400;
};

class Multigrid : public LinearOperator {
 public:
  Multigrid(const GridDims& fine, unsigned faces, real E, real nu, const MGOptions& opt = {});
  index size() const override { return levels_[0].A.size(); }
  void apply(const real* r, real* z) const override;

  int num_levels() const { return int(levels_.size()); }
  const ElasticityOperator& op(int level) const { return levels_[level].A; }
  real lambda_max(int level) const { return levels_[level].lmax; }
  // B of the finest level (4 fields of nx*ny); empty removes it.
  void set_bottom_block(const std::vector<real>& B);
  std::string describe() const;

 private:
  struct Level {
    ElasticityOperator A;
    std::vector<real> dinv;
    real lmax = 0;
    Transfer to_coarse;  // to the next level (unused on the coarsest)
    mutable std::vector<real> x, b, r, d;  // owned storage (x, b unused on level 0)
    mutable real* xp = nullptr;            // iterate and right-hand side in use:
    mutable const real* bp = nullptr;      // the caller's arrays on level 0
  };
  void vcycle(int l) const;
  void smooth(int l, bool zero_guess) const;
  void factor_coarse();
  void refresh_diagonals();  // dinv = 1 / diag(K + B) on every level
  void estimate_lmax(Level& lv);

  MGOptions opt_;
  std::vector<Level> levels_;
  Eigen::SimplicialLDLT<SparseMatrix> coarse_;
  mutable Eigen::VectorXd cb_, cx_;
};

}  // namespace tresca
