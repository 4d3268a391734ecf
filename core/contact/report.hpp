// The final, independently recomputed check of a Newton solution
// (method.md §5): S u is recomputed from scratch with a tight inner solve,
// then r = S u − b̃ and
//   true_residual      ||v̂|| of a fresh approximation step (the stopping quantity)
//   equilibrium        max_i |r_z − λ|                         [N]
//   uz_violation       max(0, −min (u_z + g))  (penetration)   [m]
//   lambda_violation   max(0, −min λ)                          [N]
//   complementarity    max_i |λ_i (u_z,i + g_i)|                [N m]
//   friction_bound     max(0, max_i |r_τ| − φ)                 [N]
//   friction_direction max over sliding nodes |r_τ + φ u_τ/|u_τ||  [N]
//   stick_slip         max over sticking nodes |u_τ|           [m]
// Node status (contact: λ − u_z > 0; stick: d_12 = 0) comes from that step.
#pragma once
#include <cstdint>
#include <vector>

#include "core/contact/semismooth.hpp"

namespace tresca {

struct FinalReport {
  real true_residual = 0, true_residual_relative = 0, btilde_norm = 0;
  real equilibrium = 0, uz_violation = 0, lambda_violation = 0, complementarity = 0;
  real friction_bound = 0, friction_direction = 0, stick_slip = 0;
  index active = 0, separated = 0, sticking = 0, sliding = 0;
  real ux_min = 0, uz_max = 0, lambda_sum = 0;
  std::vector<real> r;                // S u − b̃ (contact forces: r_τ friction, r_z = λ)
  std::vector<std::uint8_t> status;   // kContact | kStick
  SolveStats inner;                   // the tight inner solve behind S u
};

// extension (optional): E u (3N SoA) from the same tight solve; with
// `warm`, it holds an initial guess of E u on entry. The status is decided
// in the metric of R's steps (NewtonResult::scale).
FinalReport final_report(const SteklovPoincare& S, const std::vector<real>& btilde, const ContactConditions& law,
                         const NewtonResult& R, real tight_rtol = 1e-12, std::vector<real>* extension = nullptr,
                         bool warm = false);

}  // namespace tresca
