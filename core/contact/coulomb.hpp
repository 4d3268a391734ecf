// Coulomb friction by a fixed point on Tresca (issue 10): the bound of
// contact node i is phi_i = F lambda_i, lambda_i its normal contact force
// (the nodal discrete model of the Tresca case, method.md §1, with the bound
// following the pressure). Iteration m solves Tresca with phi^m by the
// semismooth* Newton method, continuing from the last solution (its u,
// lambda and tracked S u: no extra solve), then sets phi^{m+1} = F lambda^m.
// It stops when max_i |phi^{m+1} - phi^m| <= tol max_i phi^{m+1} after a
// Tresca solve to the absolute eps. The first solve goes to eps (a solve cut
// short after one step still has lambda = 0, which would look like a fixed
// point); the ones in between stop at rtol_m = 0.1 * (the last change), so
// their tolerance tightens with the fixed point's. Start: phi^0 = F lambda0 when
// an initial iterate is given (nested iteration), else phi^0 = 0
// (frictionless).
#pragma once
#include <vector>

#include "core/contact/semismooth.hpp"

namespace tresca {

struct CoulombOptions {
  real F = 0;             // friction coefficient >= 0
  real tol = 1e-6;        // on the relative change of phi
  int max_iterations = 50;
  int anderson = 2;       // depth of Anderson acceleration (0: the plain fixed point)
};

enum class CoulombReason { converged, iteration_limit, tresca_failed };
const char* to_string(CoulombReason r);

struct CoulombResult {
  CoulombReason reason = CoulombReason::iteration_limit;
  int iterations = 0;                 // Tresca solves
  std::vector<real> changes;          // relative change of phi after each
  NewtonResult last;                  // the last Tresca solve
  ContactConditions law;              // its bound phi^m (and the gap)
  long long newton_steps = 0, inner_iterations = 0;  // over all Tresca solves
  double fine_matvecs = 0;
  bool converged() const { return reason == CoulombReason::converged; }
};

// law.gap is used as given, law.phi is overwritten (phi^0 above)
CoulombResult coulomb_fixed_point(const SteklovPoincare& S, ContactConditions law,
                                  const CoulombOptions& co, const NewtonOptions& newton);

}  // namespace tresca
