// Matrix-free Q1 elasticity operator on a structured brick grid.
//
//   y = K x          on free dofs (K assembled from identical brick matrices Ke)
//   y = x            on constrained dofs (whole faces, see grid.hpp)
// with x treated as zero on constrained dofs (Dirichlet masking), so the
// result equals the assembled matrix with constrained rows/columns replaced
// by identity.
//
// How it is evaluated. Element by element, gathered per node: node p sums the
// rows of the <= 8 element matrices it belongs to,
//   y_p = sum_{e ∋ p} sum_{q ∈ e} Ke[p_loc(e), q_loc(e)] x_q ,
// which is race-free (each thread writes only its own nodes). Because every
// brick is congruent, that sum depends only on the node's per-axis boundary
// class (has left/right element, left/right neighbour constrained), so it is
// precomputed once as a 27-point stencil of 3x3 blocks per class, and only its
// nonzero couplings are kept (153 per interior node). The interior of each
// x-row shares one stencil, so the loop vectorises along x over the SoA data.
//
// Cost model per free node (interior): 153 FMAs = 306 flops (102 per dof);
// memory traffic at least 2*3*8 = 48 bytes (read x, write y; neighbour rows
// are reused from cache).
//
// elasticity_apply_ref is the textbook element loop (gather 24 values,
// multiply by Ke, scatter-add), serial. It is the test oracle.
#pragma once
#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "apply_out.hpp"
#include "grid.hpp"
#include "launch.hpp"
#include "types.hpp"

namespace tresca {

template <class T>
struct StencilGroupT {
  index off;  // b*N + dx + nx*(dy + ny*dz): input offset relative to the output node
  T c[3];     // couplings K[(p,a),(p+d,b)] for output components a = 0,1,2
};

// The stencils of one grid with coefficients of type T (double; float for the
// single-precision multigrid V-cycle, made by stencil_in_precision).
template <class T>
struct ElasticityStencilT {
  GridDims g;
  unsigned faces = 0;       // constrained faces (bitmask of Face)
  real E = 0, nu = 0;
  std::array<real, 576> Ke{};  // the brick matrix (layout: element.hpp)

  // per-axis class code of every node index: bit0 has-left-element,
  // bit1 has-right-element, bit2 left neighbour constrained, bit3 right
  // neighbour constrained, bit4 node itself on a constrained face of this axis
  Field<std::uint8_t> cls[3];
  // x-runs: maximal ranges of ix with the same x-class: [run_begin[r], run_begin[r+1])
  Field<index> run_begin;
  // stencils: id = slot[(cx*32 + cy)*32 + cz]; the groups of stencil s whose
  // nonzero outputs form mask m (1..7) are groups[first[7*s+m-1] .. first[7*s+m])
  Field<std::int32_t> slot;
  Field<std::int32_t> first;
  Field<StencilGroupT<T>> groups;
  Field<T> center;      // diagonal coefficient per stencil and component: center[3*s+a]
  Field<T> inv_center;  // its reciprocal (the smoother's Jacobi weights off the bottom plane: apply_out.hpp)

  index nodes() const { return g.nodes(); }
  index size() const { return 3 * g.nodes(); }
  // its arrays moved to space s (field.hpp)
  void move_to(Space s) {
    for (Field<std::uint8_t>& c : cls) c.move_to(s);
    run_begin.move_to(s);
    slot.move_to(s);
    first.move_to(s);
    groups.move_to(s);
    center.move_to(s);
    inv_center.move_to(s);
  }
};
using ElasticityStencil = ElasticityStencilT<real>;
using StencilGroup = StencilGroupT<real>;

// Builds Ke and all stencils needed by grid g with constrained faces.
ElasticityStencil build_elasticity_stencil(const GridDims& g, unsigned faces, real E, real nu);
// ... with the bricks' edge lengths h given (a part of a larger grid, whose
// own lengths ly/ey may round differently: core/parallel/slab.hpp)
ElasticityStencil build_elasticity_stencil(const GridDims& g, unsigned faces, real E, real nu,
                                           const std::array<real, 3>& h);
// The same stencils with coefficients rounded to T.
template <class T>
ElasticityStencilT<T> stencil_in_precision(const ElasticityStencil& k);

// Cost per output node (double fields; in_precision<float> halves the bytes):
// y = K x reads x and writes y (3 components each; neighbour rows come from
// cache), 153 FMAs; the residual b - K x also reads b.
// The smoother's Chebyshev step (apply_out.hpp) writes the new iterate over
// the one before x, which it also reads unless that one is zero
// (kChebStepExtraCost, kChebStepFromZeroExtraCost; its Jacobi weights come
// from the stencil's inv_center, in cache).
constexpr Cost kApplyCost{48, 306};
constexpr Cost kResidualCost{72, 309};
constexpr Cost kChebStepCost = kResidualCost + kChebStepExtraCost;
constexpr Cost kChebStepFromZeroCost = kResidualCost + kChebStepFromZeroExtraCost;
template <class T>
constexpr Cost apply_cost(const ApplyOut<T>& out) {
  switch (kind(out)) {
    case OutKind::step: return kChebStepCost;
    case OutKind::step_from_zero: return kChebStepFromZeroCost;
    case OutKind::residual: return kResidualCost;
    case OutKind::value: break;
  }
  return kApplyCost;
}

// y = K x for output planes iz in [z_begin, z_end) (the whole grid with
// z_begin = 0, z_end = g.nz()). With b != nullptr the residual y = b - K x is
// written instead (fused: one extra input stream, no extra pass). OpenMP over
// x-rows. Instantiated for T = double and float (vectors of Simd<T>::lanes);
// the _ref twin is double only.
template <class T>
void elasticity_apply(const ElasticityStencilT<T>& k, const T* x, T* y, index z_begin, index z_end,
                      const T* b = nullptr);
// The same for a block of node rows: planes [z_begin, z_end) x rows
// [y_begin, y_end), all of x (a rank's owned rows, read with its ghost rows
// as they are: core/fem/elasticity_operator.hpp).
struct RowBlock {
  index z_begin, z_end, y_begin, y_end;
};
// The banded apply's sweep on the host: a worker's share s of the rows of
// `rows` (numbered in order, iy fastest: host_share of its launch, launch.hpp)
// as blocks f(RowBlock) in cache order: bands of at most `band` rows, each
// swept through the share's planes in z order (the end of its first plane,
// its whole planes, the start of its last), so that a band's three input
// planes stay in L2 and its planes are read once. Every row of s once.
template <class F>
void for_each_row_band(const RowBlock& rows, Share s, index band, const F& f) {
  const index ny = rows.y_end - rows.y_begin;
  if (ny <= 0 || s.begin >= s.end) return;
  const index za = s.begin / ny, ya = s.begin % ny, zb = s.end / ny, yb = s.end % ny;  // zb: rows [0, yb) of it
  const auto block = [&](index z0, index z1, index y0, index y1) {
    if (z0 < z1 && y0 < y1) f(RowBlock{rows.z_begin + z0, rows.z_begin + z1, rows.y_begin + y0, rows.y_begin + y1});
  };
  if (za == zb) return block(za, za + 1, ya, yb);
  const index nb = (ny + band - 1) / band;
  for (index b = 0; b < nb; ++b) {
    const index y0 = ny * b / nb, y1 = ny * (b + 1) / nb;
    block(za, za + 1, std::max(y0, ya), y1);
    block(za + 1, zb, y0, y1);
    block(zb, zb + 1, y0, std::min(y1, yb));
  }
}
template <class T>
void elasticity_apply(const ElasticityStencilT<T>& k, const T* x, T* y, const RowBlock& rows, const T* b = nullptr);
// The general form: what each entry's v = (K x)_j becomes is `out`'s
// (apply_out.hpp: y = v, b - v, or a Chebyshev step of the smoother).
template <class T>
void elasticity_apply(const ElasticityStencilT<T>& k, const T* x, const ApplyOut<T>& out, const RowBlock& rows);
void elasticity_apply_ref(const ElasticityStencil& k, const real* x, real* y, index z_begin, index z_end,
                          const real* b = nullptr);

// The arrays an apply reads, as plain pointers into the stencil's Fields
// (host or device memory: where the stencil lives).
template <class T>
struct StencilView {
  GridDims g;
  const std::uint8_t* cls[3];
  const index* run_begin;
  index nruns;
  const std::int32_t* slot;
  const std::int32_t* first;
  const StencilGroupT<T>* groups;
  const T* inv_center;
};
template <class T>
StencilView<T> view(const ElasticityStencilT<T>& k);
// The same apply (K x, b - K x or a Chebyshev step) parallel over node rows, one (z, y) row per
// block with the nodes of its x-runs in `omp simd` lanes: the device's form
// (a GPU warp per row, its lanes along x: coalesced), run as a target region
// while launch_on_device() holds (x, y, b and k's arrays then in device
// memory), and on host threads otherwise (then slower than the banded
// elasticity_apply, whose explicit vectors and cache bands suit the CPU; the
// tests hold both to elasticity_apply_ref). The same per-node sums in the
// same order as elasticity_apply, equal to rounding (multiply-adds fuse
// differently in the two loops).
template <class T>
void elasticity_apply_rows(const StencilView<T>& k, const T* x, const ApplyOut<T>& out, const RowBlock& rows);

// d = diag(K) (1 on constrained dofs). Per node: writes 3 values.
constexpr Cost kDiagonalCost{24, 0};
void elasticity_diagonal(const ElasticityStencil& k, real* d);
void elasticity_diagonal_ref(const ElasticityStencil& k, real* d);

// v = 0 on the constrained faces (all components); T = double or float.
template <class T>
void zero_constrained(const GridDims& g, unsigned faces, T* v);

}  // namespace tresca
