#include "core/contact/boundary_preconditioner.hpp"

#include <stdexcept>
#include <string>

#include "kernels/launch.hpp"

namespace tresca {

namespace {
// penalty on fixed dofs relative to the diagonal of K: large enough that the
// fixed dofs decouple, small enough that Jacobi smoothing stays well scaled
constexpr real kPenalty = 1e4;
}  // namespace

BoundaryPreconditioner::BoundaryPreconditioner(const SteklovPoincare& S, const MGOptions& mg)
    : S_(S), kdiag_(S.contact_diagonal()) {
  const Problem& P = S.problem();
  // the K_ii solver's grids, transfers and smoother bounds: those were
  // estimated on K with the contact face free (steklov.cpp), and they bound
  // D^-1 (K + B) for every B of update() below: B's penalties are diagonal
  // and its 2x2 blocks H at most twice their diagonal, under the bounds'
  // floor 2.3 (smoothing.hpp), so the Rayleigh quotient of K + B over its
  // diagonal is at most the larger of K's and 2
  mg_ = std::make_unique<Multigrid>(S.interior_multigrid().hierarchy(),
                                    elasticity_on(P.dirichlet_faces, P.spec.E, P.spec.nu), mg, &S.interior_multigrid());
}

void BoundaryPreconditioner::update(const Field<real>& h_placed, const Field<std::uint8_t>& fixed_placed,
                                    const Field<std::uint8_t>& free_mask) {
  const Problem& P = S_.problem();
  const GridDims& g = P.grid;
  const index M = g.nx() * g.ny(), p = S_.contact_nodes(), first = S_.first_contact_node();
  if (index(h_placed.size()) != 3 * p || index(fixed_placed.size()) != 3 * p || index(free_mask.size()) != 3 * p)
    throw std::invalid_argument("BoundaryPreconditioner::update: h, fixed and free must have 3p = " +
                                std::to_string(3 * p) + " entries");
  const std::vector<real> h = h_placed.to_vector();
  const std::vector<std::uint8_t> fixed = fixed_placed.to_vector();
  // B over the whole bottom plane: this rank's contact nodes, then (several
  // ranks) the sum of every rank's, which own disjoint nodes
  std::vector<real> B(4 * M, 0.0);
  for (index c = 0; c < p; ++c) {
    const index n = P.contact_grid_node(first + c);  // bottom plane: grid node index = plane index
    B[0 * M + n] = fixed[c] ? kPenalty * kdiag_[c] : h[c];
    B[1 * M + n] = (fixed[c] || fixed[p + c]) ? 0 : h[p + c];
    B[2 * M + n] = fixed[p + c] ? kPenalty * kdiag_[p + c] : h[2 * p + c];
    B[3 * M + n] = fixed[2 * p + c] ? kPenalty * kdiag_[2 * p + c] : 0;
  }
  S_.comm().sum(B.data(), int(B.size()));
  mg_->set_bottom_block(B);
  free_ = free_mask;
}

void BoundaryPreconditioner::apply(const real* r, real* z) const {
  mg_->apply_at(S_.contact_rows(), r, z);
  const std::uint8_t* free = free_.data();
  for_each_entry("newton-step preconditioner mask", size(), Cost{9, 0}, [=](index i) {
    if (!free[i]) z[i] = 0;
  });
}

}  // namespace tresca
