// The geometric-multigrid V-cycle of multigrid.hpp on y-slabs (issue 12,
// phase 2): the same hierarchy (GridHierarchy::build), smoother (Chebyshev
// of degree d in D^{-1} A, bounds from a Lanczos estimate), transfers
// (trilinear, non-nested), coarsest solve (Eigen LDLT, double) and
// precision (MGOptions::precision: single by default, as there: the
// V-cycle in float inside the double CG), with the work split over the ranks:
//
// * fine levels are distributed: each rank holds its slab of the level
//   (make_slab of that level's grid) and applies A with ghost exchange
//   (distributed_elasticity.hpp);
// * a level with fewer than 2 node rows per rank or fewer than
//   `min_nodes_per_rank` nodes per rank, and every coarser one, is
//   agglomerated onto rank 0: the fine residual is gathered there, rank 0
//   alone runs the coarse levels (no messages inside) down to the coarsest
//   (factorised and solved there), and broadcasts the correction;
// * transfers between distributed levels fetch the rows that neighbours
//   own (row_fetch.hpp): the coarse rows a fine slab interpolates from, the
//   fine rows a coarse slab restricts from.
//
// One rank: every level whole, i.e. multigrid.hpp's V-cycle (up to the
// Lanczos start vector, here a hash of the global index so that it does
// not depend on the rank count).
#pragma once
#include <Eigen/SparseCholesky>
#include <memory>
#include <string>
#include <vector>

#include "core/fem/assembly.hpp"
#include "core/fem/elasticity_operator.hpp"
#include "core/parallel/distributed_elasticity.hpp"
#include "core/parallel/row_fetch.hpp"
#include "core/solvers/multigrid.hpp"

namespace tresca {

// whether a grid is split over the ranks (a DistributedMultigrid's level 0
// is then distributed): more than one rank, at least 2 node rows and
// min_nodes_per_rank nodes per rank
bool worth_distributing(const GridDims& g, const Comm& comm, index min_nodes_per_rank = 2048);

class DistributedMultigrid : public LinearOperator {
 public:
  // like: take the smoother bounds from that multigrid (same grid, options
  // and rank count) instead of estimating them, as Multigrid's
  DistributedMultigrid(const GridDims& fine, unsigned faces, real E, real nu, const MGOptions& opt = {},
                       const Comm& comm = Comm::world(), index min_nodes_per_rank = 2048,
                       const DistributedMultigrid* like = nullptr);
  ~DistributedMultigrid() override;
  // on level-0 local vectors: the slab's local box if level 0 is
  // distributed, the whole grid if not (one rank)
  index size() const override;
  void apply(const real* r, real* z) const override;
  // the fine operator K on the same vectors (zero ghost rows on output),
  // without the bottom block
  const LinearOperator& op() const;
  // B of the finest level over the WHOLE bottom plane (4 fields of nx*ny,
  // elasticity_operator.hpp), the same on every rank (built from replicated
  // contact data, so no messages): every level gets its projection P^T B
  // (as Multigrid::set_bottom_block) and each rank keeps its rows of it
  void set_bottom_block(const std::vector<real>& B);
  bool fine_distributed() const;
  const Slab& fine_slab() const;  // level 0's slab (the whole grid when replicated)
  int num_levels() const { return int(levels_.size()); }
  int distributed_levels() const;
  double cycle_work() const;  // as Multigrid::cycle_work
  real lmax(int level) const;
  std::string describe() const;

 private:
  struct Level;
  template <class T>
  struct Work;
  template <class T>
  void build_work();
  template <class T>
  void refresh_work();
  void refresh_diagonals();
  void factor_coarse();
  void estimate_lmax(Level& lv);
  template <class T>
  void residual(const Level& lv, const T* b, const T* x, T* r) const;
  template <class T>
  void smooth(int l, bool zero_guess) const;
  template <class T>
  void vcycle(int l) const;
  // level l is the first whole (not distributed) level on several ranks:
  // it and the coarser ones are computed by rank 0 alone
  bool agglomerated(int l) const;

  MGOptions opt_;
  const Comm& comm_;
  unsigned faces_;
  std::shared_ptr<const GridHierarchy> grids_;
  std::vector<std::unique_ptr<Level>> levels_;
  ElasticityOperator op0_;  // K of a replicated level 0 (op())
  Eigen::SimplicialLDLT<SparseMatrix> coarse_;
  mutable Eigen::VectorXd cb_, cx_;
};

}  // namespace tresca
