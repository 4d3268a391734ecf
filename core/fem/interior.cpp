#include "core/fem/interior.hpp"

#include "kernels/vector_ops.hpp"
#include "core/util/profile.hpp"

namespace tresca {

InteriorSolution solve_interior_elasticity(const Problem& P, const Multigrid& mg, real rtol) {
  const double t0 = wall_time();
  const index n = P.dofs();
  InteriorSolution s;
  s.u.resize(n);
  std::vector<real> b(P.load);
  zero_constrained(P.grid, P.interior_faces, b.data());
  CGOptions o;
  o.rtol = rtol;
  CGWorkspace ws;
  s.stats = pcg(mg.op(0), &mg, b.data(), s.u.data(), o, ws);
  s.seconds = wall_time() - t0;
  s.fine_matvecs = s.stats.operator_applications + s.stats.preconditioner_applications * mg.cycle_work();
  std::vector<real>& r = ws.r;  // reuse as scratch
  mg.op(0).residual(b.data(), s.u.data(), r.data());
  s.relative_residual = s.stats.rhs_norm > 0 ? norm2(n, r.data()) / s.stats.rhs_norm : norm2(n, r.data());
  return s;
}

}  // namespace tresca
