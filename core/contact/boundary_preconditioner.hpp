// Preconditioner for the reduced Newton system (S + H)_FF Δu_F = r_F
// (method.md §4) on the contact boundary.
//
// Why it works: for any block B living on the contact dofs only, the Schur
// complement identity gives ((K + B)^{-1})_cc = (S + B)^{-1} exactly. With
// B = H on the free dofs F and a large penalty on the dofs the Newton step
// fixes, ((K + B)^{-1})_FF → ((S + H)_FF)^{-1}. One multigrid V-cycle for
// K + B (K with u = 0 on x = 0 only) is spectrally equivalent to (K + B)^{-1}
// uniformly in h, so the outer CG iteration count stays flat under refinement.
//
//   M r = mask_F( V-cycle(K + B) [ r on the bottom face, 0 elsewhere ] )_c
//
// Cost per apply: one fine V-cycle (about one inner CG iteration), i.e. about
// a tenth of one S application.
//
// The V-cycle runs on the K_ii solver's hierarchy (grids, transfers, row
// fetches, smoother bounds, which were estimated to hold for K + B too:
// boundary_preconditioner.cpp), shared. Several ranks: each rank fills B at
// its contact nodes and one allreduce of the plane (4 nx ny values per
// Newton step) gives every rank the whole of it.
#pragma once
#include <cstdint>
#include <vector>

#include <memory>

#include "core/multigrid/multigrid.hpp"
#include "core/contact/steklov.hpp"

namespace tresca {

class BoundaryPreconditioner : public LinearOperator {
 public:
  BoundaryPreconditioner(const SteklovPoincare& S, const MGOptions& mg = {});
  index size() const override { return S_.size(); }
  void apply(const real* r, real* z) const override;

  // work of one apply in fine-grid matvec equivalents (one V-cycle of K + B)
  double apply_work() const { return mg_->cycle_work(); }

  // Rebuild B for the current Newton system: h (3 blocks of p: h11, h12, h22
  // on sliding nodes), `fixed` (3p bytes, 1 where the increment is known)
  // and `free` mask (3p bytes) of the reduced system, where the launches
  // run. B is set up on the host (the multigrid's bottom block and its
  // coarse projections are host set-up: multigrid.hpp), so h and fixed
  // cross once per Newton step; the applies stay where the launches run.
  void update(const Field<real>& h, const Field<std::uint8_t>& fixed, const Field<std::uint8_t>& free_mask);

 private:
  const SteklovPoincare& S_;
  std::unique_ptr<Multigrid> mg_;  // K + B
  std::vector<real> kdiag_;  // diag of K at this rank's contact nodes (3 blocks)
  Field<std::uint8_t> free_;
};

}  // namespace tresca
