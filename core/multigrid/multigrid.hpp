// Geometric multigrid V-cycle for the Q1 elasticity operator on the brick
// grid, used as a preconditioner (one V-cycle with zero initial guess per
// apply), on one rank or on y-slabs of several.
//
// Hierarchy (GridHierarchy, built once per solve and shared by every
// multigrid on that grid: the K_ii solver and the Newton-step
// preconditioner): each coarser grid has ceil(e/2) elements along every axis
// whose spacing is within 1.5x of the finest (semi-coarsening for
// anisotropic bricks; all axes on the benchmark's near-cubic bricks),
// non-nested when e is odd, the same box and constrained faces, and is
// rediscretised (same brick formula, coarse h). Transfers are trilinear
// interpolation and its exact transpose (kernels/transfer.hpp). Coarsening
// stops when a grid has at most `coarse_nodes` nodes; that grid is solved
// directly (coarse_solver.hpp: Eigen's sparse LDLT of the assembled K,
// factorised once; a bottom block is a dense update of K's Schur
// complement on the bottom plane).
//
// Ranks: a level is either whole or split into y-slabs (slab.hpp), one per
// rank. One rank is the case where every level is whole. On several ranks,
// fine levels with at least 2 node rows and `min_nodes_per_rank` nodes per
// rank are split: each rank holds its slab and applies A with a halo
// exchange (elasticity_operator.hpp); the first whole level and every
// coarser one are agglomerated onto rank 0 (the residual gathered there,
// rank 0 alone runs the coarse levels, the correction broadcast). Transfers
// between split levels fetch the rows that neighbours own (row_fetch.hpp).
// Every line above the exchanges and the reductions is the same for one
// rank and many.
//
// Device: in a device run (one rank, kernels/launch.hpp) the levels after
// the finest with fewer than device_min_nodes() nodes are held and run on
// the host, where their sweeps cost less than GPU launches; the V-cycle
// enters the first of them as it enters an agglomerated level: its
// right-hand side crosses to the host, its correction back (a copy each a
// V-cycle).
//
// Smoother: Chebyshev polynomial of degree `degree` in D^{-1}A (Jacobi),
// targeting [lmax/range, lmax]; lmax from 15 steps of Jacobi-PCG (Lanczos)
// in the V-cycle's precision, times 1.15, from a start vector that depends
// on the global dof index only (the same on any rank count). The same
// polynomial pre and post keeps the V-cycle symmetric, so it is a valid CG
// preconditioner.
//
// Optional bottom-face block B (elasticity_operator.hpp): coarse levels get
// the lumped Galerkin projection B_c = P^T B_f (restricted per entry), which
// preserves row sums of P^T B P. The coarse factorisation is redone.
//
// Precision: the V-cycle runs in double, or in single precision (float
// stencils, transfers, smoother vectors; input and output converted at the
// finest level, or taken and given in float by a caller that keeps float
// copies, apply_in_float: CG, cg.hpp; the coarsest grid is solved in double). Single precision
// halves the bytes and doubles the vector lanes of every V-cycle kernel. As
// a preconditioner of a double-precision CG it only has to be a good
// approximate inverse: its rounding (relative 1e-7) is far below what the
// V-cycle itself leaves, so the CG iteration count does not change (tests:
// MultigridCG.SinglePrecisionVCycleKeepsIterationsAndAccuracy).
//
// Cost per V-cycle on a level with n dofs: (2*degree) applies of A, plus
// residual apply, one restriction and one prolongation: about
// (2*degree+1) * 306/3 + 20 flops per dof; the hierarchy adds about 1/7.
// The smoother's steps run fused into the apply (smoothing.hpp,
// kernels/apply_out.hpp): no residual vector written and read back, about
// 30 % less memory traffic a step; only the zero guess's first step is a
// vector update. The prolongation writes the corrected iterate into the
// vector from which the post-smoother's steps, alternating between two
// vectors, end in x, so that smoother needs no residual sweep either.
#pragma once
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "kernels/launch.hpp"
#include "kernels/transfer.hpp"
#include "core/fem/assembly.hpp"
#include "core/fem/elasticity_operator.hpp"
#include "core/multigrid/coarse_solver.hpp"
#include "core/parallel/comm.hpp"
#include "core/parallel/row_fetch.hpp"

namespace tresca {

enum class Precision { double_precision, single_precision };
const char* to_string(Precision p);

struct MGOptions {
  int degree = 3;
  real range = 15;
  index coarse_nodes = 400;  // used when the hierarchy is built (GridHierarchy::build)
  Precision precision = Precision::single_precision;
};

// whether a grid is split over the ranks of comm: more than one rank, at
// least 2 node rows and min_nodes_per_rank nodes per rank
constexpr index kMinNodesPerRank = 2048;
bool worth_distributing(const GridDims& g, const Comm& comm, index min_nodes_per_rank = kMinNodesPerRank);
// the ranks a fine grid's operators are split over: comm where
// worth_distributing, else Comm::self() (every rank holds the grid whole)
const Comm& split_over(const GridDims& g, const Comm& comm);
// how the ranks of comm hold g, for a run's header: "y-slabs", or `whole`
// (what the run does with a grid it does not split: "each rank solves the
// whole mesh") and why; "one rank" on one
std::string rank_layout(const GridDims& g, const Comm& comm, const std::string& whole);

// The grids of a multigrid hierarchy, how each is held by the ranks, and
// the transfers between them.
struct GridHierarchy {
  struct Level {
    GridDims grid;             // the whole grid
    Slab slab;                 // this rank's part: its slab if split, else the whole grid
    bool distributed = false;  // split over the ranks
    // held and run on the host while the finer levels run on the device: in
    // a device run, a level other than the finest with fewer than
    // device_min_nodes() nodes (kernels/launch.hpp), where a launch would
    // cost more than the host's sweep; false in a host run
    bool on_host = false;
  };
  // from level l to l + 1
  struct Link {
    Transfer whole;                 // between the whole grids, on the host (each Newton
                                    // step's P^T B; on the device it cost a copy there and back)
    Transfer restrict_t, prolong_t; // the rows this rank computes (whole: `whole`)
    // rows that other ranks own: the fine rows the coarse rows restrict from,
    // the coarse rows the fine rows interpolate from (null: none needed)
    std::shared_ptr<RowFetch> fetch_fine, fetch_coarse;
  };
  std::vector<Level> levels;  // finest first
  std::vector<Link> to_coarse;
  const Comm* comm = nullptr;
  // where the launches ran when it was built: where the levels that are not
  // on_host, and their transfers, are run (a Multigrid refuses another)
  Space space = Space::host;
  // level l is the first whole level on several ranks: it and the coarser
  // ones are computed by rank 0 alone
  bool agglomerated(int l) const;
  // level l is the first on the host in a device run: its right-hand side
  // is restricted on the device and crosses to the host, its correction
  // crosses back
  bool crosses_to_host(int l) const { return levels[l].on_host && (l == 0 || !levels[l - 1].on_host); }
  std::vector<GridDims> grids() const;  // the levels' whole grids
  int distributed_levels() const;
  // semi-coarsening until a grid has at most coarse_nodes nodes; levels
  // split over comm's ranks where worth_distributing (Comm::self(): all
  // whole); with the launches on the device (one rank), the levels after
  // the finest with fewer than device_min_nodes nodes on the host, their
  // transfers made there (none given: tresca::device_min_nodes(), read in
  // a device run only)
  static std::shared_ptr<const GridHierarchy> build(const GridDims& fine, index coarse_nodes,
                                                    const Comm& comm = Comm::self(),
                                                    index min_nodes_per_rank = kMinNodesPerRank,
                                                    std::optional<index> device_min_nodes = std::nullopt);
};

// The grids of a hierarchy from `fine`: semi-coarsened until one has at
// most coarse_nodes nodes (GridHierarchy::build)
std::vector<GridDims> coarsening(const GridDims& fine, index coarse_nodes = MGOptions{}.coarse_nodes);
// The anisotropy semi-coarsening cannot remove: on the first level of
// coarsening(fine) whose thinnest axis has one element left (a plate's
// thickness), the largest ratio of an element's edge along an axis with
// more than one element to that thickness; 1 where no such level is made.
// Above about 4 the point smoother leaves errors smooth across the
// thickness and rough along the plate, which the coarser levels, wider
// still, do not represent: the boundary Newton system's V-cycle of K + B
// (the contact face free) stalls on thin plates of wide elements
// (perf/RESULTS.md §0ze).
real unresolved_anisotropy(const GridDims& fine, index coarse_nodes = MGOptions{}.coarse_nodes);

// The description of the operator a multigrid preconditions: its
// rediscretisation on this rank's part of any grid of the hierarchy (the
// finest included). Other materials or constrained faces plug in here;
// per-node boundary terms come in through set_bottom_block.
using Rediscretisation = std::function<ElasticityOperator(const Slab&)>;
// isotropic elasticity (E, nu) with the given constrained faces on every grid
Rediscretisation elasticity_on(unsigned faces, real E, real nu);

class Multigrid : public LinearOperator {
 public:
  // The smoother's spectral bounds (the largest eigenvalue of D^-1 A per
  // level) are estimated on op, or
  // - bounds_of: on that operator instead, one whose matrix holds op's as
  //   a principal submatrix (op with more constrained faces: its Jacobi-
  //   scaled spectrum lies below the larger one's, Cauchy interlacing), so
  //   that a multigrid built `like` this one may share them (the K_ii
  //   solver's, estimated on K with the contact face free, bound the K + B
  //   of the Newton step's preconditioner, boundary_preconditioner.hpp; on
  //   a mesh one element thick, K_ii's own were a third too low for it and
  //   its CG broke down, perf/RESULTS.md §0zd);
  // - like: taken from that multigrid (its hierarchy must be `grids`),
  //   whose bounds must hold for op, which also shares its V-cycle's work
  //   vectors (in the same precision): one V-cycle of either may not run
  //   inside the other's
  Multigrid(std::shared_ptr<const GridHierarchy> grids, const Rediscretisation& op, const MGOptions& opt = {},
            const Multigrid* like = nullptr, const Rediscretisation& bounds_of = {});
  // builds its own hierarchy (opt.coarse_nodes) for elasticity on `fine`
  Multigrid(const GridDims& fine, unsigned faces, real E, real nu, const MGOptions& opt = {},
            const Comm& comm = Comm::self());
  // on level-0 vectors: this rank's slab (the whole grid on one rank)
  index size() const override { return levels_[0].A.size(); }
  void apply(const real* r, real* z) const override;
  // a V-cycle in single precision takes r and gives z in float as well
  // (operator.hpp): the V-cycle on the caller's arrays, without converting
  bool works_in_float() const override { return opt_.precision == Precision::single_precision; }
  void apply_in_float(const float* r, float* z) const override;
  // The V-cycle restricted to some level-0 entries, E^T M E: its
  // right-hand side is r[k] at entry at[k] and zero elsewhere, and z[k] its
  // result at entry at[k] (k < at.size(); `at` where the launches run, rows
  // this rank owns). No full-size vector of the caller's: the level-0 work
  // vectors (made on first use in double precision) hold both.
  void apply_at(const Field<index>& at, const real* r, real* z) const;

  int num_levels() const { return int(levels_.size()); }
  const MGOptions& options() const { return opt_; }
  const std::shared_ptr<const GridHierarchy>& hierarchy() const { return grids_; }
  // the sum over the ranks for dots of level-0 vectors: the ranks if level 0
  // is split, null if every rank holds it whole
  const Reduction* reduction() const { return grids_->levels[0].distributed ? grids_->comm : nullptr; }
  // work of one V-cycle in applications of the finest operator: 2*degree
  // residual applies on every level but the coarsest, weighted by its size
  // (transfers, vector updates and the coarse solve not counted)
  double cycle_work() const;
  // the (double-precision) operator of a level on this rank's part; op(0)
  // is the operator this V-cycle preconditions
  const ElasticityOperator& op(int level) const { return levels_[level].A; }
  real lmax(int level) const { return levels_[level].lmax; }
  // B of the finest level over the WHOLE bottom plane (4 fields of nx*ny,
  // elasticity_operator.hpp), the same on every rank; every level gets its
  // projection P^T B. Empty removes it.
  void set_bottom_block(const std::vector<real>& B);
  std::string describe() const;

 private:
  struct Level {
    ElasticityOperator A;  // double (coarse factorisation, op()) and float
    real lmax = 0;
  };
  // The V-cycle's vectors of one level in precision T: the scratch of one
  // V-cycle, which the multigrids of one hierarchy built `like` one another
  // share (their V-cycles never overlap: apply checks it)
  template <class T>
  struct Work {
    Field<T> x, b, r, fine_rows, coarse_rows;
    T* xp = nullptr;        // iterate and right-hand side in use: the caller's
    const T* bp = nullptr;  // arrays on level 0 (a double one, or apply_in_float), host_x and host_b on
                            // the first host level of a device run (x and b: their device
                            // copies, which the finer level's transfers write and read)
    Field<T> host_x, host_b;
  };
  template <class T>
  struct Cycle {
    std::vector<Work<T>> levels;
    bool busy = false;  // a V-cycle is running in these vectors
  };
  // what the multigrid holds in precision T (the V-cycles' one is built)
  template <class T>
  struct InPrecision {
    std::shared_ptr<Cycle<T>> cycle;  // shared with a multigrid built `like` this one
    std::vector<Field<T>> dinv;       // per level: 1 / diag(K + B), 0 on ghost rows
  };
  template <class T>
  InPrecision<T>& held() { return std::get<InPrecision<T>>(held_); }
  template <class T>
  const InPrecision<T>& held() const { return std::get<InPrecision<T>>(held_); }
  template <class T>
  std::vector<Work<T>>& work() const { return held<T>().cycle->levels; }  // (scratch: written by const applies)
  template <class T>
  void build_work(const Multigrid* like);
  template <class T>
  void refresh_work();  // dinv from the levels' operators
  template <class T>
  void residual(int l, const T* b, T* x, T* r) const;
  template <class T>
  void smooth(int l, bool zero_guess, const T* in = nullptr) const;
  template <class T>
  void vcycle(int l) const;
  // vcycle(l) where level l is held: where it is the first held whole on
  // several ranks (agglomerated), rank 0 alone runs it and broadcasts its
  // correction xp; where it is the first on the host in a device run, its
  // right-hand side crosses to the host and its correction back
  template <class T>
  void vcycle_where_held(int l) const;
  bool on_host(std::size_t l) const { return grids_->levels[l].on_host; }
  template <class T>
  void vcycle_at(const Field<index>& at, const real* r, real* z) const;
  template <class T>
  void restrict_residual(int l) const;
  template <class T>
  T* prolongate_correction(int l) const;  // into the post-smoother's entry; returns it
  void check_launch_space() const;  // throws std::logic_error: built for one space, applied in the other
  void factor_coarse();
  // the largest eigenvalue of D^-1 A of level l's operator A on its part
  // of the grid (Lanczos in precision T, smoothing.hpp), A and D^-1 where
  // level l runs
  template <class T>
  real estimate_lmax(int l, const ElasticityOperator& A, const Field<T>& dinv) const;
  const Comm& comm() const { return *grids_->comm; }

  MGOptions opt_;
  std::shared_ptr<const GridHierarchy> grids_;
  std::vector<Level> levels_;
  std::tuple<InPrecision<double>, InPrecision<float>> held_;
  CoarseSolver coarse_;  // on rank 0 (every rank when all levels are whole)
  mutable Eigen::VectorXd cb_, cx_;
};

}  // namespace tresca
