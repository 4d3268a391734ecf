#include "core/contact/coulomb.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Dense>

#include "kernels/vector_ops.hpp"

namespace tresca {

const char* to_string(CoulombReason r) {
  switch (r) {
    case CoulombReason::converged: return "converged";
    case CoulombReason::iteration_limit: return "fixed_point_iteration_limit";
    case CoulombReason::tresca_failed: return "tresca_solve_failed";
  }
  return "?";
}

CoulombResult coulomb_fixed_point(const SteklovPoincare& S, ContactConditions law,
                                  const CoulombOptions& co, const NewtonOptions& newton) {
  if (!(co.F >= 0) || !std::isfinite(co.F))
    throw std::invalid_argument("coulomb: the friction coefficient " + std::to_string(co.F) + " must be >= 0 and finite");
  const index p = S.size() / 3;
  CoulombResult C;
  NewtonOptions no = newton;
  if (newton.lambda0)
    law.set_coulomb_bound(co.F, *newton.lambda0);
  else
    std::fill(law.phi.begin(), law.phi.end(), real(0));
  // the first solve and the last go to eps; in between, a solve stops at
  // rtol = 0.1 * the last change of phi (the tolerances tighten together)
  real change = INFINITY;
  std::vector<real> G(p), f(p), G_prev, f_prev;
  std::vector<std::vector<real>> dF, dG;  // Anderson's differences, oldest first
  for (int m = 0;; ++m) {
    const bool to_eps = m == 0 || change <= co.tol;
    no.rtol = to_eps ? newton.rtol : std::max(newton.rtol, real(0.1) * change);
    NewtonResult R = semismooth_newton(S, law, no);
    C.iterations = m + 1;
    C.newton_steps += R.iterations;
    C.inner_iterations += R.inner_iterations;
    C.fine_matvecs += R.fine_matvecs;
    C.last = std::move(R);
    C.law = law;
    const NewtonResult& L = C.last;
    no.inner_tightening = L.inner_tightening;  // (the next solve starts where this one ended)
    if (!L.converged()) {
      C.reason = CoulombReason::tresca_failed;
      return C;
    }
    // G = F lambda^m, the residual f = G - phi^m and its relative size
    real dmax = 0, pmax = 0;
    for (index i = 0; i < p; ++i) {
      G[i] = co.F * std::max(real(0), L.lambda[i]);
      f[i] = G[i] - law.phi[i];
      dmax = std::max(dmax, std::abs(f[i]));
      pmax = std::max(pmax, G[i]);
    }
    dmax = S.max(dmax);  // over all ranks' contact nodes
    pmax = S.max(pmax);
    const real last_change = change;
    change = pmax > 0 ? dmax / pmax : 0;
    C.changes.push_back(change);
    // next bound: Anderson's combination of the last steps, phi = G - dG gamma
    // with gamma minimising |f - dF gamma|, kept >= 0; plain phi = G when
    // there is no history or the change grew (the history is then dropped)
    if (co.anderson > 0 && m > 0 && change < last_change) {
      dF.push_back(f);
      dG.push_back(G);
      for (index i = 0; i < p; ++i) {
        dF.back()[i] -= f_prev[i];
        dG.back()[i] -= G_prev[i];
      }
      if (int(dF.size()) > co.anderson) {
        dF.erase(dF.begin());
        dG.erase(dG.begin());
      }
    } else {
      dF.clear();
      dG.clear();
    }
    f_prev = f;
    G_prev = G;
    law.phi = G;
    const int k = int(dF.size());
    if (k > 0) {
      const HostLaunches host;  // (its differences are host vectors, also in a device run)
      Eigen::MatrixXd A(k, k);
      Eigen::VectorXd rhs(k);
      for (int a = 0; a < k; ++a) {
        rhs[a] = S.sum(dot(p, dF[a].data(), f.data()));
        for (int b = 0; b < k; ++b) A(a, b) = S.sum(dot(p, dF[a].data(), dF[b].data()));
      }
      const Eigen::VectorXd gamma = A.ldlt().solve(rhs);
      if (gamma.allFinite())
        for (index i = 0; i < p; ++i) {
          real v = G[i];
          for (int a = 0; a < k; ++a) v -= gamma[a] * dG[a][i];
          law.phi[i] = std::max(real(0), v);
        }
    }
    // converged: a solve to eps whose lambda reproduces its own bound
    if (to_eps && change <= co.tol) {
      C.reason = CoulombReason::converged;
      return C;
    }
    if (m + 1 >= co.max_iterations) {
      C.reason = CoulombReason::iteration_limit;
      return C;
    }
    // continue from this solution, its residual and body (the body taken
    // by the next solve, whose result replaces this one)
    no.u0 = &L.u;
    no.lambda0 = &L.lambda;
    no.r0 = &L.r;
    no.body0 = &C.last.body;
    no.force_scale = L.force_scale;
  }
}

}  // namespace tresca
