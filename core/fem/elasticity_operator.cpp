#include "core/fem/elasticity_operator.hpp"

#include <stdexcept>
#include <string>

#include "kernels/boundary_block.hpp"
#include "core/util/profile.hpp"

namespace tresca {

ElasticityOperator::ElasticityOperator(const GridDims& g, unsigned faces, real E, real nu)
    : k_(build_elasticity_stencil(g, faces, E, nu)) {}

void ElasticityOperator::apply(const real* x, real* y) const { apply_planes(x, y, 0, k_.g.nz()); }

void ElasticityOperator::apply_planes(const real* x, real* y, index z_begin, index z_end) const {
  const GridDims& g = k_.g;
  {
    const double nodes = double(g.nx()) * double(g.ny()) * double(z_end - z_begin);
    ScopedTimer t(Kernel::apply, nodes * kApplyCost);
    elasticity_apply(k_, x, y, z_begin, z_end);
  }
  if (!B_.empty() && z_begin == 0 && z_end > 0) {
    const double m = double(g.nx()) * double(g.ny());
    ScopedTimer t(Kernel::apply_boundary, m * kBottomBlockCost);
    bottom_block_apply<real>(g, 1, B_.data(), x, y);
  }
}

void ElasticityOperator::residual(const real* b, const real* x, real* r) const {
  const GridDims& g = k_.g;
  {
    const double nodes = double(g.nodes());
    ScopedTimer t(Kernel::apply, nodes * kResidualCost);
    elasticity_apply(k_, x, r, 0, g.nz(), b);
  }
  if (!B_.empty()) {
    const double m = double(g.nx()) * double(g.ny());
    ScopedTimer t(Kernel::apply_boundary, m * kBottomBlockCost);
    bottom_block_apply<real>(g, -1, B_.data(), x, r);
  }
}

void ElasticityOperator::set_bottom_block(std::vector<real> B) {
  const GridDims& g = k_.g;
  if (!B.empty() && index(B.size()) != 4 * g.nx() * g.ny())
    throw std::invalid_argument("bottom block has " + std::to_string(B.size()) + " entries, expected 4 x " +
                                std::to_string(g.nx() * g.ny()));
  B_ = std::move(B);
  if (B_.empty()) return;
  const index M = g.nx() * g.ny();
  for (index iy = 0; iy < g.ny(); ++iy)
    for (index ix = 0; ix < g.nx(); ++ix)
      if (node_constrained(g, k_.faces, ix, iy, 0))
        for (int f = 0; f < 4; ++f) B_[f * M + ix + g.nx() * iy] = 0;
}

std::vector<real> ElasticityOperator::diagonal() const {
  std::vector<real> d(size());
  elasticity_diagonal(k_, d.data());
  if (!B_.empty()) {
    const GridDims& g = k_.g;
    const index M = g.nx() * g.ny(), N = g.nodes();
    for (index n = 0; n < M; ++n) {
      d[n] += B_[n];
      d[N + n] += B_[2 * M + n];
      d[2 * N + n] += B_[3 * M + n];
    }
  }
  return d;
}

}  // namespace tresca
