#include "core/contact/report.hpp"

#include <algorithm>
#include <cmath>

#include "kernels/contact_maps.hpp"
#include "kernels/launch.hpp"
#include "kernels/vector_ops.hpp"

namespace tresca {

FinalReport final_report(const SteklovPoincare& S, const ContactConditions& law, const NewtonResult& R,
                         real tight_rtol, Field<real>* body, real tolerance) {
  const index p = S.size() / 3;
  const std::vector<real>& phi = law.phi;
  FinalReport F;
  std::vector<real> v(4 * p), w(4 * p), d(3 * p);
  const real* units = R.units.empty() ? nullptr : R.units.data();
  F.tolerance = tolerance > 0 ? tolerance : R.tolerance;
  const bool warm = body && !body->empty();
  if (body) body->resize(S.full_size());
  real* U = body ? body->data() : nullptr;
  {  // the one solve, where the launches run; the rest is p-sized work on host copies
    const Field<real> u = placed_field<real>(R.u);
    Field<real> r(3 * p);
    F.inner = S.residual(u.data(), r.data(), tight_rtol, U, warm ? U : nullptr);
    F.r = r.to_vector();
  }
  HostLaunches host;
  F.status.resize(p);
  // the residual is the paper's |v̂| either way; the status (which nodes are
  // in contact, which stick) is decided in Newton's metric R.scale, so that
  // it does not depend on the units where a node is on the edge of two states
  const ResidualNorms norms = approximation_step(p, law.law(R.kink_contact), R.scale.empty() ? nullptr : R.scale.data(), units,
                                                R.u.data(), R.lambda.data(), F.r.data(), v.data(), w.data(), d.data(),
                                                F.status.data());
  F.true_residual_consistent = std::sqrt(S.sum(norms.consistent));
  F.true_residual = R.stop == StopRule::consistent ? F.true_residual_consistent : std::sqrt(S.sum(norms.paper));
  F.btilde_norm = R.force_scale;
  F.resolution = tight_rtol * R.force_scale;
  F.true_residual_relative = F.btilde_norm > 0 ? F.true_residual / F.btilde_norm : F.true_residual;
  F.ux_min = INFINITY;
  F.uz_max = -INFINITY;
  const real tol = F.tolerance;
  for (index i = 0; i < p; ++i) {
    const real ux = R.u[i], uy = R.u[p + i], uz = R.u[2 * p + i], lam = R.lambda[i];
    const real rx = F.r[i], ry = F.r[p + i], rz = F.r[2 * p + i];
    const real s = units ? units[i] : 1;  // [N/m]: a length in consistent units
    const real gap = law.gap[i];
    const real eq = std::abs(rz - lam), pen = std::max(real(0), -(uz + gap)), neg = std::max(real(0), -lam);
    F.equilibrium = std::max(F.equilibrium, eq);
    F.uz_violation = std::max(F.uz_violation, pen);
    F.lambda_violation = std::max(F.lambda_violation, neg);
    F.complementarity = std::max(F.complementarity, std::abs(lam * (uz + gap)));
    const real rt = std::hypot(rx, ry), ut = std::hypot(ux, uy);
    F.friction_bound = std::max(F.friction_bound, rt - phi[i]);
    real worst = std::max({eq, s * pen, neg, std::min(std::abs(lam), s * std::abs(uz + gap)), rt - phi[i]});
    // Tresca's friction law holds at every node, in contact or not
    if (F.status[i] & kStick) {
      F.stick_slip = std::max(F.stick_slip, ut);
      worst = std::max(worst, s * ut);
    } else if (s * ut > tol) {
      const real dir = std::hypot(rx + phi[i] * ux / ut, ry + phi[i] * uy / ut);
      F.friction_direction = std::max(F.friction_direction, dir);
      worst = std::max(worst, dir);
    } else {
      F.slip_unresolved += 1;
    }
    F.kkt_force = std::max(F.kkt_force, worst);
    F.ux_min = std::min(F.ux_min, ux);
    F.uz_max = std::max(F.uz_max, uz);
    F.lambda_sum += lam;
  }
  const StateCounts states = count_states(p, F.status.data());
  F.separated = states.separated;
  F.sticking = states.stick;
  F.sliding = states.slip;
  // over all ranks (each holds its own contact nodes; identity on one rank)
  for (real* m : {&F.equilibrium, &F.uz_violation, &F.lambda_violation, &F.complementarity, &F.friction_bound,
                  &F.friction_direction, &F.stick_slip, &F.uz_max, &F.kkt_force})
    *m = S.max(*m);
  F.ux_min = -S.max(-F.ux_min);
  for (index* c : {&F.separated, &F.sticking, &F.sliding, &F.slip_unresolved}) *c = index(S.sum(real(*c)));
  F.active = F.sticking + F.sliding;
  F.lambda_sum = S.sum(F.lambda_sum);
  F.friction_bound = std::max(F.friction_bound, real(0));
  F.kkt_ok = F.kkt_force <= tol && F.true_residual_consistent <= tol;
  return F;
}

}  // namespace tresca
