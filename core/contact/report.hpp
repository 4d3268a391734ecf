// The final, independently recomputed check of a Newton solution
// (method.md §5): r = S u − b̃ is recomputed with a tight inner solve
// (SteklovPoincare::residual: its CG checks the true residual of its
// initial guess, so a warm start gives the same accuracy), then
//   true_residual      the stopping quantity of a fresh approximation step
//                      (|w| [N], or the paper's |v̂| under its rule)
//   equilibrium        max_i |r_z − λ|                         [N]
//   uz_violation       max(0, −min (u_z + g))  (penetration)   [m]
//   lambda_violation   max(0, −min λ)                          [N]
//   complementarity    max_i |λ_i (u_z,i + g_i)|                [N m]
//   friction_bound     max(0, max_i |r_τ| − φ)                 [N]
//   friction_direction max over sliding nodes whose slip is resolved
//                      (s_i |u_τ| > tolerance) |r_τ + φ u_τ/|u_τ||  [N]
//   stick_slip         max over sticking nodes |u_τ|           [m]
// Node status (contact: λ − u_z > 0; stick: d_12 = 0) comes from that step.
// The verdict: every field in consistent units [N] (a length times the
// node's stiffness s_i; complementarity as min(λ, s (u_z + g))) and |w|
// at most `tolerance` (kkt_force is the largest of them): a run is
// converged only if its own check says so (run.hpp).
#pragma once
#include <cstdint>
#include <vector>

#include "core/contact/semismooth.hpp"

namespace tresca {

struct FinalReport {
  real true_residual = 0, true_residual_relative = 0, btilde_norm = 0;  // relative to |b̃| (R.force_scale)
  // what the check resolves: r is the contact force of a body whose interior
  // equilibrium is verified to tight_rtol, so r is known to ~tight_rtol |b̃|
  real resolution = 0;
  real equilibrium = 0, uz_violation = 0, lambda_violation = 0, complementarity = 0;
  real friction_bound = 0, friction_direction = 0, stick_slip = 0;
  real true_residual_consistent = 0;  // |w| [N] of the fresh r, whatever the stopping rule
  real kkt_force = 0;      // the largest KKT violation in consistent units [N]
  real tolerance = 0;      // what it was checked against [N]
  bool kkt_ok = true;      // kkt_force and true_residual_consistent <= tolerance
  index slip_unresolved = 0;  // sliding nodes with s_i |u_τ| <= tolerance: no direction to check
  // contact states (contact_maps.hpp: contact_state): active = sticking + sliding
  index active = 0, separated = 0, sticking = 0, sliding = 0;
  real ux_min = 0, uz_max = 0, lambda_sum = 0;
  std::vector<real> r;                // S u − b̃ (contact forces: r_τ friction, r_z = λ)
  std::vector<std::uint8_t> status;   // kContact | kStick
  SolveStats inner;                   // the tight inner solve behind r
};

// body (optional): the body's displacement E u + K_ii^{-1} l_i from the
// same tight solve (steklov.hpp: residual); if not empty on entry, the
// solve's initial guess (Newton's NewtonResult::body). The status is decided
// in the metric of R's steps (NewtonResult::scale). tolerance [N]: the
// verdict's (0: R.tolerance).
FinalReport final_report(const SteklovPoincare& S, const ContactConditions& law, const NewtonResult& R,
                         real tight_rtol = 1e-12, Field<real>* body = nullptr, real tolerance = 0);

}  // namespace tresca
