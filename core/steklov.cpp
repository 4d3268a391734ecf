#include "steklov.hpp"

#include <stdexcept>
#include <string>

#include "../kernels/vector_ops.hpp"
#include "profile.hpp"

namespace tresca {

SteklovPoincare::SteklovPoincare(const Problem& P, const MGOptions& mg)
    : P_(P),
      p_(P.contact_nodes()),
      K_(P.grid, P.dirichlet_faces, P.spec.E, P.spec.nu),
      mg_(P.grid, P.interior_faces, P.spec.E, P.spec.nu, mg) {
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

SolveStats SteklovPoincare::solve_interior(const real* rhs, real* z) const {
  ScopedTimer t(Kernel::inner_cg);
  CGOptions o;
  o.rtol = inner_rtol_;
  o.max_iterations = 500;
  SolveStats st = pcg(mg_.op(0), &mg_, rhs, z, o, ws_);
  stats_.solves += 1;
  stats_.iterations += st.iterations;
  if (!st.ok()) {
    stats_.failures += 1;
    stats_.last_failure = st.reason;
  }
  return st;
}

void SteklovPoincare::apply(const real* v, real* Sv) const {
  const GridDims& g = P_.grid;
  const index n = 3 * P_.nodes(), N = P_.nodes(), plane = g.nx() * g.ny();
  fill(n, 0, w_.data());
  scatter(v, w_.data());
  // t = -K_ic v on plane 1, zero elsewhere
  fill(n, 0, t_.data());
  K_.apply_planes(w_.data(), t_.data(), 1, std::min<index>(2, g.nz()));
  for (int a = 0; a < 3; ++a) scale(plane, -1, t_.data() + a * N + plane);
  zero_constrained(g, P_.interior_faces, t_.data());
  solve_interior(t_.data(), z_.data());
  // u = w + z ; Sv = (K u)_c on plane 0
  axpy(n, 1, w_.data(), z_.data());
  K_.apply_planes(z_.data(), t_.data(), 0, 1);
  gather(t_.data(), Sv);
}

std::vector<real> SteklovPoincare::condensed_load(real rtol) const {
  const real keep = inner_rtol_;
  inner_rtol_ = rtol;
  const index n = 3 * P_.nodes();
  std::vector<real> li(P_.load);
  zero_constrained(P_.grid, P_.interior_faces, li.data());
  solve_interior(li.data(), z_.data());
  inner_rtol_ = keep;
  K_.apply_planes(z_.data(), t_.data(), 0, 1);
  std::vector<real> b(3 * p_), lc(3 * p_);
  gather(t_.data(), b.data());
  gather(P_.load.data(), lc.data());
  for (index i = 0; i < 3 * p_; ++i) b[i] = lc[i] - b[i];
  (void)n;
  return b;
}

std::vector<real> SteklovPoincare::recover(const real* uc, real rtol) const {
  const GridDims& g = P_.grid;
  const index n = 3 * P_.nodes();
  fill(n, 0, w_.data());
  scatter(uc, w_.data());
  // rhs = l_i - K_ic u_c  (K_ic u_c lives on plane 1)
  fill(n, 0, t_.data());
  K_.apply_planes(w_.data(), t_.data(), 1, std::min<index>(2, g.nz()));
  xpay(n, P_.load.data(), -1, t_.data());
  zero_constrained(g, P_.interior_faces, t_.data());
  const real keep = inner_rtol_;
  inner_rtol_ = rtol;
  std::vector<real> u(n);
  solve_interior(t_.data(), u.data());
  inner_rtol_ = keep;
  axpy(n, 1, w_.data(), u.data());
  return u;
}

}  // namespace tresca
