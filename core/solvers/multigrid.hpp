// Geometric multigrid V-cycle for the Q1 elasticity operator on the brick grid,
// used as a preconditioner (one V-cycle with zero initial guess per apply).
//
// Hierarchy (GridHierarchy, shared): each coarser grid has ceil(e/2) elements along every axis whose
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
// Precision: the V-cycle runs in double, or in single precision (float
// stencils, transfers, smoother vectors; input and output converted at the
// finest level; the coarsest grid is solved in double). Single precision
// halves the bytes and doubles the vector lanes of every V-cycle kernel. As a
// preconditioner of a double-precision CG it only has to be a good
// approximate inverse: its rounding (relative 1e-7) is far below what the
// V-cycle itself leaves, so the CG iteration count does not change (tests:
// MultigridCG.SinglePrecisionVCycleKeepsIterationsAndAccuracy).
//
// Cost per V-cycle on a level with n dofs: (2*degree) applies of A, plus
// residual apply, one restriction and one prolongation: about
// (2*degree+1) * 306/3 + 20 flops per dof; the hierarchy adds about 1/7.
#pragma once
#include <Eigen/SparseCholesky>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "kernels/transfer.hpp"
#include "core/fem/assembly.hpp"
#include "core/fem/elasticity_operator.hpp"

namespace tresca {

enum class Precision { double_precision, single_precision };
const char* to_string(Precision p);

struct MGOptions {
  int degree = 3;
  real range = 15;
  index coarse_nodes = 400;  // used when the hierarchy is built (GridHierarchy::build)
  Precision precision = Precision::single_precision;
};

// The grids of a multigrid hierarchy and the transfers between them, for one
// fine grid; built once and shared by every multigrid on that grid (the K_ii
// solver and the Newton-step preconditioner use the same one).
struct GridHierarchy {
  std::vector<GridDims> grids;      // finest first
  std::vector<Transfer> to_coarse;  // grids[l] -> grids[l + 1]
  // semi-coarsening until a grid has at most coarse_nodes nodes
  static std::shared_ptr<const GridHierarchy> build(const GridDims& fine, index coarse_nodes);
};

// The description of the operator a multigrid preconditions: its
// rediscretisation on any grid of the hierarchy (the finest included). Other
// materials or constrained faces plug in here; per-node boundary terms come
// in through set_bottom_block.
using Rediscretisation = std::function<ElasticityOperator(const GridDims&)>;
// isotropic elasticity (E, nu) with the given constrained faces on every grid
Rediscretisation elasticity_on(unsigned faces, real E, real nu);

class Multigrid : public LinearOperator {
 public:
  Multigrid(std::shared_ptr<const GridHierarchy> grids, const Rediscretisation& op, const MGOptions& opt = {});
  // the same, with the smoother's spectral bounds taken from `like` (its
  // hierarchy must be `grids`) instead of estimated: for a multigrid of an
  // operator whose Jacobi-scaled spectrum is the same up to boundary terms.
  // The K + B preconditioner of the Newton step and the K_ii solver measure
  // lmax within 0.3% of each other on every level (level 10: 2.972 and
  // 2.975), well inside the 1.15 margin; the estimate is 15 fine-level
  // applies and 45 vector sweeps (1.5 s at level 13)
  Multigrid(std::shared_ptr<const GridHierarchy> grids, const Rediscretisation& op, const MGOptions& opt,
            const Multigrid& like);
  // builds its own hierarchy (opt.coarse_nodes) for elasticity on `fine`
  Multigrid(const GridDims& fine, unsigned faces, real E, real nu, const MGOptions& opt = {});
  index size() const override { return levels_[0].A.size(); }
  void apply(const real* r, real* z) const override;

  int num_levels() const { return int(levels_.size()); }
  const MGOptions& options() const { return opt_; }
  const std::shared_ptr<const GridHierarchy>& hierarchy() const { return grids_; }
  // work of one V-cycle in applications of the finest operator: 2*degree
  // residual applies on every level but the coarsest, weighted by its size
  // (transfers, vector updates and the coarse solve not counted)
  double cycle_work() const;
  // the (double-precision) operator of a level; op(0) is the operator this
  // V-cycle preconditions
  const ElasticityOperator& op(int level) const { return levels_[level].A; }
  // B of the finest level (4 fields of nx*ny); empty removes it.
  void set_bottom_block(const std::vector<real>& B);
  std::string describe() const;

 private:
  Multigrid(std::shared_ptr<const GridHierarchy> grids, const Rediscretisation& op, const MGOptions& opt,
            const Multigrid* like);
  struct Level {
    ElasticityOperator A;  // double: lmax estimate, coarse factorisation, op()
    real lmax = 0;
  };
  // The V-cycle's data on one level in precision T.
  template <class T>
  struct Work {
    ElasticityStencilT<T> k;
    std::vector<T> B, dinv;                // bottom block (may be empty), 1 / diag(K + B)
    mutable std::vector<T> x, b, r, d;     // owned storage (x, b unused on a double level 0)
    mutable T* xp = nullptr;               // iterate and right-hand side in use: the
    mutable const T* bp = nullptr;         // caller's arrays on a double level 0
  };
  template <class T>
  std::vector<Work<T>>& work();
  template <class T>
  const std::vector<Work<T>>& work() const;
  template <class T>
  void build_work();
  template <class T>
  void refresh_work();  // B and dinv from the levels' operators
  template <class T>
  void residual(int l, const T* b, const T* x, T* r) const;
  template <class T>
  void smooth(int l, bool zero_guess) const;
  template <class T>
  void vcycle(int l) const;
  void factor_coarse();
  void estimate_lmax(Level& lv);

  MGOptions opt_;
  std::shared_ptr<const GridHierarchy> grids_;
  std::vector<Level> levels_;
  std::vector<Work<double>> work_d_;
  std::vector<Work<float>> work_s_;
  Eigen::SimplicialLDLT<SparseMatrix> coarse_;
  mutable Eigen::VectorXd cb_, cx_;
};

}  // namespace tresca
