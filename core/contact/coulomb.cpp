#include "core/contact/coulomb.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace tresca {

const char* to_string(CoulombReason r) {
  switch (r) {
    case CoulombReason::converged: return "converged";
    case CoulombReason::iteration_limit: return "fixed_point_iteration_limit";
    case CoulombReason::tresca_failed: return "tresca_solve_failed";
  }
  return "?";
}

CoulombResult coulomb_fixed_point(const SteklovPoincare& S, const std::vector<real>& btilde, ContactConditions law,
                                  const CoulombOptions& co, const NewtonOptions& newton) {
  if (!(co.F >= 0) || !std::isfinite(co.F))
    throw std::invalid_argument("coulomb: the friction coefficient " + std::to_string(co.F) + " must be >= 0 and finite");
  const index p = S.size() / 3;
  CoulombResult C;
  NewtonOptions no = newton;
  for (index i = 0; i < p; ++i) law.phi[i] = newton.lambda0 ? co.F * std::max(real(0), (*newton.lambda0)[i]) : 0;
  // the first solve and the last go to eps; in between, a solve stops at
  // rtol = 0.1 * the last change of phi (the tolerances tighten together)
  real change = INFINITY;
  for (int m = 0;; ++m) {
    const bool to_eps = m == 0 || change <= co.tol;
    no.rtol = to_eps ? newton.rtol : std::max(newton.rtol, real(0.1) * change);
    NewtonResult R = semismooth_newton(S, btilde, law, no);
    C.iterations = m + 1;
    C.newton_steps += R.iterations;
    C.inner_iterations += R.inner_iterations;
    C.fine_matvecs += R.fine_matvecs;
    C.last = std::move(R);
    C.law = law;
    const NewtonResult& L = C.last;
    if (!L.converged()) {
      C.reason = CoulombReason::tresca_failed;
      return C;
    }
    // phi^{m+1} = F lambda^m and its relative change
    real dmax = 0, pmax = 0;
    for (index i = 0; i < p; ++i) {
      const real next = co.F * std::max(real(0), L.lambda[i]);
      dmax = std::max(dmax, std::abs(next - law.phi[i]));
      pmax = std::max(pmax, next);
      law.phi[i] = next;
    }
    change = pmax > 0 ? dmax / pmax : 0;
    C.changes.push_back(change);
    // converged: a solve to eps whose lambda reproduces its own bound
    if (to_eps && change <= co.tol) {
      C.reason = CoulombReason::converged;
      return C;
    }
    if (m + 1 >= co.max_iterations) {
      C.reason = CoulombReason::iteration_limit;
      return C;
    }
    // continue from this solution and its tracked S u
    no.u0 = &L.u;
    no.lambda0 = &L.lambda;
    no.Su0 = &L.Su;
    no.extension0 = nullptr;
  }
}

}  // namespace tresca
