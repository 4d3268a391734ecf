#include "core/fem/elasticity_operator.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "kernels/boundary_block.hpp"
#include "kernels/vector_ops.hpp"
#include "core/util/profile.hpp"

namespace tresca {

ElasticityOperator::ElasticityOperator(const GridDims& g, unsigned faces, real E, real nu)
    : ElasticityOperator(make_slab(g, 0, 1), faces, E, nu) {}

ElasticityOperator::ElasticityOperator(const Slab& s, unsigned faces, real E, real nu)
    : slab_(s),
      global_faces_(faces),
      halo_(s),
      // the global grid's spacing: a slab's ly/ey may round in the last bit (slab.hpp)
      k_(build_elasticity_stencil(s.local, s.local_faces(faces), E, nu, {s.global.hx(), s.global.hy(), s.global.hz()})),
      kf_(stencil_in_precision<float>(k_)) {}

template <>
const ElasticityStencilT<double>& ElasticityOperator::stencil_in<double>() const {
  return k_;
}
template <>
const ElasticityStencilT<float>& ElasticityOperator::stencil_in<float>() const {
  return kf_;
}
template <>
const Field<double>& ElasticityOperator::block_in<double>() const {
  return B_;
}
template <>
const Field<float>& ElasticityOperator::block_in<float>() const {
  return Bf_;
}

template <class T>
void ElasticityOperator::apply_rows(const T* x, const ApplyOut<T>& out, index z_begin, index z_end) const {
  const GridDims& g = slab_.local;
  const index first = slab_.lo, last = slab_.lo + slab_.owned_rows();  // owned local rows
  {
    const double nodes = double(g.nx()) * double(last - first) * double(z_end - z_begin);
    ScopedTimer t(Kernel::apply, nodes * in_precision<T>(apply_cost(out)));
    elasticity_apply<T>(stencil_in<T>(), x, out, RowBlock{z_begin, z_end, first, last});
  }
  const Field<T>& B = block_in<T>();
  if (!B.empty() && z_begin == 0 && z_end > 0) {  // B is 0 on ghost rows
    const double m = double(g.nx()) * double(g.ny());
    ScopedTimer t(Kernel::apply_boundary, m * in_precision<T>(kBottomBlockCost));
    bottom_block_apply<T>(g, B.data(), x, out);
  }
  if (z_begin == 0 && z_end == g.nz()) halo_.zero_ghosts(out.y);
}

template void ElasticityOperator::apply_rows<double>(const double*, const ApplyOut<double>&, index, index) const;
template void ElasticityOperator::apply_rows<float>(const float*, const ApplyOut<float>&, index, index) const;

void ElasticityOperator::apply_planes(const real* x, real* y, index z_begin, index z_end) const {
  apply_rows<real>(x, operator_out(y), z_begin, z_end);
}

void ElasticityOperator::set_bottom_block(const std::vector<real>& B) {
  const GridDims& G = slab_.global;
  const index M = G.nx() * G.ny();
  if (!B.empty() && index(B.size()) != 4 * M)
    throw std::invalid_argument("bottom block has " + std::to_string(B.size()) + " entries, expected 4 x " +
                                std::to_string(M));
  B_ = {};  // (given back first: the new blocks below are the old ones again, BlockCache)
  Bf_ = {};
  if (B.empty()) return;
  std::vector<real> Bz = B;
  zero_constrained_bottom_block(G, global_faces_, Bz);
  const GridDims& g = slab_.local;
  const index Ml = g.nx() * g.ny(), row0 = slab_.y_begin - slab_.lo;
  std::vector<real> Bl(4 * Ml, 0.0);
  for (int f = 0; f < 4; ++f)  // owned rows only: ghost rows stay 0
    std::copy_n(Bz.data() + f * M + G.nx() * slab_.y_begin, G.nx() * slab_.owned_rows(),
                Bl.data() + f * Ml + g.nx() * (slab_.y_begin - row0));
  B_ = placed_field<real>(Bl);
  Bf_ = placed_field<float>(Bl);
}

void zero_constrained_bottom_block(const GridDims& g, unsigned faces, std::vector<real>& B) {
  if (B.empty()) return;
  const index M = g.nx() * g.ny();
  for (index iy = 0; iy < g.ny(); ++iy)
    for (index ix = 0; ix < g.nx(); ++ix)
      if (node_constrained(g, faces, ix, iy, 0))
        for (int f = 0; f < 4; ++f) B[f * M + ix + g.nx() * iy] = 0;
}

Field<real> ElasticityOperator::diagonal() const {
  Field<real> d(size());
  elasticity_diagonal(k_, d.data());
  if (!B_.empty()) bottom_block_diagonal(slab_.local, B_.data(), d.data());
  halo_.zero_ghosts(d.data());
  return d;
}

JacobiPreconditioner::JacobiPreconditioner(const ElasticityOperator& K) : inv_(K.diagonal()) {
  reciprocal_or_zero(size(), inv_.data(), inv_.data());
}

void JacobiPreconditioner::apply(const real* r, real* z) const { hadamard(size(), inv_.data(), r, z); }

}  // namespace tresca
