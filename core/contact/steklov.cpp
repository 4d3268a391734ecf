#include "core/contact/steklov.hpp"

#include <stdexcept>
#include <string>

#include "kernels/vector_ops.hpp"
#include "core/util/profile.hpp"

namespace tresca {

SteklovPoincare::SteklovPoincare(const Problem& P, const MGOptions& mg)
    : P_(P),
      p_(P.contact_nodes()),
      K_(P.grid, P.dirichlet_faces, P.spec.E, P.spec.nu),
      mg_(GridHierarchy::build(P.grid, mg.coarse_nodes), elasticity_on(P.interior_faces, P.spec.E, P.spec.nu), mg) {
  const index n = 3 * P.nodes();
  w_.assign(n, 0);
  t_.assign(n, 0);
  z_.assign(n, 0);
}

void SteklovPoincare::scatter(const real* vc, real* full) const {
  const index N = P_.nodes();
  for (index c = 0; c < p_; ++c) {
    const index n = P_.contact_grid_node(c);
    for (int a = 0; a < 3; ++a) full[a * N + n] = vc[a * p_ + c];
  }
}

void SteklovPoincare::gather(const real* full, real* vc) const {
  const index N = P_.nodes();
  for (index c = 0; c < p_; ++c) {
    const index n = P_.contact_grid_node(c);
    for (int a = 0; a < 3; ++a) vc[a * p_ + c] = full[a * N + n];
  }
}

SolveStats SteklovPoincare::solve_interior(const real* rhs, real* z, real rtol, const real* guess) const {
  ScopedTimer t(Kernel::inner_cg);
  CGOptions o;
  o.rtol = rtol;
  if (guess) {
    copy(3 * P_.nodes(), guess, z);
    zero_constrained(P_.grid, P_.interior_faces, z);  // the guess of an extension carries v on plane 0
    o.zero_initial_guess = false;
  }
  o.max_iterations = 500;
  return pcg(mg_.op(0), &mg_, rhs, z, o, ws_);
}

void SteklovPoincare::set_plane(real* v, index iz, const real* src) const {
  const GridDims& g = P_.grid;
  const index plane = g.nx() * g.ny(), N = P_.nodes();
  for (int a = 0; a < 3; ++a) {
    real* dst = v + a * N + iz * plane;
    if (src)
      copy(plane, src + a * N + iz * plane, dst);
    else
      fill<real>(plane, 0, dst);
  }
}

SolveStats SteklovPoincare::apply(const real* v, real* Sv, real rtol, real* extension, const real* guess) const {
  // Invariants between calls: w_ is zero off the contact nodes, t_ is zero
  // off plane 1, so only plane-sized work surrounds the inner solve.
  const GridDims& g = P_.grid;
  const index N = P_.nodes(), plane = g.nx() * g.ny();
  scatter(v, w_.data());
  // t = -K_ic v lives on plane 1 (w_ is zero on the x = 0 nodes, so are t's)
  K_.apply_planes(w_.data(), t_.data(), 1, 2);
  for (int a = 0; a < 3; ++a) scale(plane, -1, t_.data() + a * N + plane);
  const SolveStats st = solve_interior(t_.data(), z_.data(), rtol, guess);
  // u = w + z: z vanishes on the constrained plane 0, where w lives
  set_plane(z_.data(), 0, w_.data());
  // Sv = (K u)_c on plane 0, then restore t_'s invariant
  K_.apply_planes(z_.data(), t_.data(), 0, 1);
  gather(t_.data(), Sv);
  set_plane(t_.data(), 0, nullptr);
  if (extension) copy(3 * N, z_.data(), extension);
  return st;
}

double SteklovPoincare::apply_work(long long inner_iterations) const {
  return double(inner_iterations) * (1 + mg_.cycle_work()) + 2.0 / double(P_.grid.nz());
}

SolveStats SteklovPoincare::condensed_load(real rtol, std::vector<real>& b, std::vector<real>* interior,
                                           const real* guess) const {
  std::vector<real> li(P_.load);
  zero_constrained(P_.grid, P_.interior_faces, li.data());
  const SolveStats st = solve_interior(li.data(), z_.data(), rtol, guess);
  K_.apply_planes(z_.data(), t_.data(), 0, 1);
  std::vector<real> lc(3 * p_);
  b.resize(3 * p_);
  gather(t_.data(), b.data());
  set_plane(t_.data(), 0, nullptr);
  gather(P_.load.data(), lc.data());
  for (index i = 0; i < 3 * p_; ++i) b[i] = lc[i] - b[i];
  if (interior) interior->assign(z_.begin(), z_.end());
  return st;
}

}  // namespace tresca
