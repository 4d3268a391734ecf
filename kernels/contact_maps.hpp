// Per-contact-node maps of the semismooth* Newton method (method.md §3–4),
// with a Tresca bound phi_i and an initial gap g_i >= 0 to the rigid obstacle
// per contact node (non-penetration u_z + g_i >= 0; the benchmark: g = 0).
//
// Unknowns per node i: x = (u_x, u_y, u_z, lambda); r = S u − b̃ (3 blocks of p).
// F_12 = r_12, F_3 = r_3 − lambda, F_4 = u_z + g.
// Approximation step in the metric of a stiffness s_i > 0 [N/m] per node
// (the paper's problems (i)–(iii) with ½|v|² replaced by ½|v|²·s for the
// displacement unknowns and ½v²/s for lambda; s = 1 is the paper's step):
//   z = x_12 − F_12/s,  d_12 = max(0, 1 − phi/(s|z|)) z,  v_12 = d_12 − x_12
//   v_3 = −F_3
//   d_4 = max(0, lambda − s (u_z + g)),                   v_4 = d_4 − lambda
// The paper's step (s = 1) adds forces [N] to displacements [m]: with nodal
// forces of 1e7 N a force residual of 1 N outweighs any displacement. With
// s = diag(S) the comparison is in consistent units (issue 9, item 4). Both
// have the same fixed points: d = x iff x solves the problem.
// Node status: sticking iff d_12 = 0; in contact iff d_4 > 0. A node's
// state for every output is one of separated / stick / slip
// (contact_state: separation first; a separated node's friction bit still
// matters to Tresca's law, whose bound does not depend on contact).
//
// Residual in consistent units [N] (the stopping rule and the line search's
// merit, method.md §5): the step at the units' stiffness s_i with its
// displacement parts turned into forces,
//   w = (s v_12, v_3, v_4)  at scale s,  |w| = 0 iff x solves the problem;
// the paper's |v̂| (s = 1) adds metres to newtons.
// Newton blocks (10): sliding H_1 = phi/|d|^3 [[d2², −d1 d2], [−d1 d2, d1²]].
//
// DATA LAYOUT: SoA. u, r: [x | y | z] blocks of p; lambda, phi, gap, scale: p;
// v: 4 blocks of p [v1 | v2 | v3 | v4]; d: 3 blocks [d1 | d2 | d4]; status:
// p bytes (bit0 contact, bit1 stick). Every array lives where the launches
// run (launch.hpp): the kernels below are launches.
#pragma once
#include <cstdint>

#include "types.hpp"

namespace tresca {

enum : std::uint8_t { kContact = 1, kStick = 2 };

constexpr Cost kApproximationStepCost{177, 78};  // per contact node: reads u, lambda, r, phi, gap, s, units; writes v, w, d, status

// The contact law of p nodes: Tresca bounds phi (N) and gaps (m), p values each.
// kink_contact: a node on the kink lambda - s (u_z + g) = 0 (lambda = 0 on
// the obstacle: every node of a cold start) is taken in contact, the
// element of the generalised derivative whose step stays on the obstacle
// (the line search's merit then falls along it); false: method.md's d_4 > 0,
// the paper's literal method (--table).
struct ContactLaw {
  const real* phi;
  const real* gap;
  bool kink_contact = true;
};

enum class ContactState : std::uint8_t { separated, stick, slip };
inline ContactState contact_state(std::uint8_t status) {
  return !(status & kContact) ? ContactState::separated : (status & kStick) ? ContactState::stick : ContactState::slip;
}
inline const char* to_string(ContactState s) {
  return s == ContactState::separated ? "separated" : s == ContactState::stick ? "stick" : "slip";
}
// the three states' counts over p statuses (contact = stick + slip)
struct StateCounts {
  index separated = 0, stick = 0, slip = 0;
  index contact() const { return stick + slip; }
};
StateCounts count_states(index p, const std::uint8_t* status);

// Coulomb's bound at lambda: phi_i = F max(0, lambda_i)
void coulomb_bound(index p, real F, const real* lambda, real* phi);

// |v̂|^2 of the paper's step (s = 1, its rule (11)) and |w|^2 of the
// residual in consistent units [N^2] (deterministic order)
struct ResidualNorms {
  real paper = 0, consistent = 0;
};

// v: the paper's v̂ (s = 1); w: the residual in consistent units at the
// stiffness `units` (nullptr: w = v̂); d and status: the step at scale s
// (nullptr: s = 1, and then d_12 = x_12 + v_12, d_4 = lambda + v_4).
ResidualNorms approximation_step(index p, const ContactLaw& law, const real* scale, const real* units, const real* u,
                                 const real* lambda, const real* r, real* v, real* w, real* d, std::uint8_t* status);

// The contact part of the forward-backward envelope of the Tresca problem
// min ½ uᵀS u − b̃ᵀu + Σ phi_i |u_τ| subject to u_z + g >= 0, in the metric of
// the step's stiffness s_i (the line search's merit where it resolves,
// semismooth.cpp): per node
//   e_i(u, r) = min over y with y_z + g_i >= 0 of
//               r·(y − u) + ½ s_i |y − u|² + phi_i |y_τ|,
// r = S u − b̃, whose minimiser y is the proximal point of the approximation
// step (y_τ = max(0, 1 − phi/(s |z|)) z with z = u_τ − r_τ/s, y_z + g =
// max(0, u_z + g − r_z/s)). The envelope is ½ uᵀ(r − b̃) + Σ e_i; along
// u + a du, r + a S du its change is a du·r + ½ a² du·S du plus
//   change = Σ e_i(u + a du, r + a S du) − e_i(u, r)
// returned here with size = Σ |e_i(u + a du, ...)| + |e_i(u, ...)|, the
// terms' magnitude, which bounds the sum's rounding.
struct EnvelopeChange {
  real change = 0, size = 0;
};
constexpr Cost kEnvelopeChangeCost{128, 80};  // per contact node and sum: reads u, r, du, S du, phi, gap, s
EnvelopeChange envelope_change(index p, const ContactLaw& law, const real* scale, real a, const real* u, const real* r,
                               const real* du, const real* Sdu);

// The 2x2 block H_1 of a sliding node from d_12 (entries h11, h12, h22).
inline void sliding_block(real phi, real d1, real d2, real& h11, real& h12, real& h22) {
  const real n2 = d1 * d1 + d2 * d2;
  const real c = phi / (n2 * __builtin_sqrt(n2));
  h11 = c * d2 * d2;
  h12 = -c * d1 * d2;
  h22 = c * d1 * d1;
}

}  // namespace tresca
