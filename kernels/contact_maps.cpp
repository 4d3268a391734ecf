#include "contact_maps.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "launch.hpp"
#include "vector_ops.hpp"

namespace tresca {

namespace {
// d_12, d_4 of the approximation step at scale s (contact_maps.hpp)
struct NodeStep {
  real d1, d2, d4;
  bool stick, contact;
};
inline NodeStep node_step(real s, real phi, real x1, real x2, real x3, real x4, real r1, real r2, bool kink_contact) {
  const real z1 = x1 - r1 / s, z2 = x2 - r2 / s;
  const real nz = std::sqrt(z1 * z1 + z2 * z2);
  const real t = s * nz > phi ? 1 - phi / (s * nz) : 0;
  // contact where lambda - s (u_z + g) > 0, and on the kink (= 0) if asked
  const real c = x4 - s * x3;
  return {t * z1, t * z2, std::max(real(0), c), t == 0, kink_contact ? c >= 0 : c > 0};
}
}  // namespace

StateCounts count_states(index p, const std::uint8_t* status) {
  // three counts where the status lives (each a deterministic sum)
  auto count = [=](ContactState which) {
    return index(sum_over_entries(p, Cost{1, 1}, [=](index i) { return real(contact_state(status[i]) == which); }));
  };
  StateCounts c;
  c.separated = count(ContactState::separated);
  c.stick = count(ContactState::stick);
  c.slip = count(ContactState::slip);
  return c;
}

void coulomb_bound(index p, real F, const real* lambda, real* phi) {
  for_each_entry(p, Cost{16, 2}, [=](index i) { phi[i] = F * (lambda[i] > 0 ? lambda[i] : real(0)); });
}

ResidualNorms approximation_step(index p, const ContactLaw& law, const real* scale, const real* units, const real* u,
                                 const real* lambda, const real* r, real* v, real* w, real* d, std::uint8_t* status) {
  TRESCA_ASSERT(p >= 0 && (p == 0 || (law.phi != nullptr && law.gap != nullptr)));
  // per-node work in parallel, then the deterministic blocked sum of v.v.
  // (A block per node: on a GPU one lane of a warp does a node. In simd
  // lanes, for_each_entry, GCC 12's nvptx backend stops with an internal
  // compiler error in make_decl_rtl; p is the contact face, small.)
  // (The test oracle is the dense reference Newton in tests/test_newton.cpp.)
  for_each_block(p, double(p) * kApproximationStepCost, [=](index i) {
    // x3 enters through F_4 = u_z + g
    const real x1 = u[i], x2 = u[p + i], x3 = u[2 * p + i] + law.gap[i], x4 = lambda[i];
    const real r1 = r[i], r2 = r[p + i];
    const NodeStep paper = node_step(1, law.phi[i], x1, x2, x3, x4, r1, r2, law.kink_contact);
    v[i] = paper.d1 - x1;
    v[p + i] = paper.d2 - x2;
    v[2 * p + i] = -(r[2 * p + i] - x4);
    v[3 * p + i] = paper.d4 - x4;
    const NodeStep unit = units ? node_step(units[i], law.phi[i], x1, x2, x3, x4, r1, r2, law.kink_contact) : paper;
    const real su = units ? units[i] : 1;
    w[i] = su * (unit.d1 - x1);
    w[p + i] = su * (unit.d2 - x2);
    w[2 * p + i] = v[2 * p + i];
    w[3 * p + i] = unit.d4 - x4;
    const NodeStep step = scale ? (scale == units ? unit : node_step(scale[i], law.phi[i], x1, x2, x3, x4, r1, r2, law.kink_contact))
                                : paper;
    d[i] = step.d1;
    d[p + i] = step.d2;
    d[2 * p + i] = step.d4;
    status[i] = std::uint8_t((step.contact ? kContact : 0) | (step.stick ? kStick : 0));
  });
  return {dot(4 * p, v, v), dot(4 * p, w, w)};
}

}  // namespace tresca
