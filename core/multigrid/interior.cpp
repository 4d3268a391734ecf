#include "core/multigrid/interior.hpp"

#include <algorithm>
#include <cmath>

#include "kernels/vector_ops.hpp"
#include "core/util/profile.hpp"

namespace tresca {

InteriorSolution solve_interior_elasticity(const Problem& P, const Multigrid& mg, real rtol) {
  const double t0 = wall_time();
  const ElasticityOperator& K = mg.op(0);
  const index n = K.size();
  const Reduction* reduce = mg.reduction();
  auto norm = [&](const real* v) { return std::sqrt(reduce ? reduce->sum(dot(n, v, v)) : dot(n, v, v)); };
  InteriorSolution s;
  s.u.resize(n);
  Field<real> b = load_on(P, K.slab());
  zero_constrained(K.grid(), K.faces(), b.data());
  K.zero_ghosts(b.data());
  CGOptions o;
  o.rtol = rtol;
  o.reduction = reduce;
  CGWorkspace ws;
  s.stats = pcg(K, &mg, b.data(), s.u.data(), o, ws);
  s.seconds = wall_time() - t0;
  s.fine_matvecs = s.stats.operator_applications + s.stats.preconditioner_applications * mg.cycle_work();
  Field<real>& r = ws.r;  // reuse as scratch
  K.update_ghosts(s.u.data());
  K.residual(b.data(), s.u.data(), r.data());
  s.relative_residual = s.stats.rhs_norm > 0 ? norm(r.data()) / s.stats.rhs_norm : norm(r.data());
  K.zero_ghosts(s.u.data());
  for (real v : s.u.to_vector()) s.max_abs_u = std::max(s.max_abs_u, std::abs(v));
  s.max_abs_u = real(mg.hierarchy()->comm->max(s.max_abs_u));
  return s;
}

}  // namespace tresca
