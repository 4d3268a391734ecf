#include "contact_maps.hpp"

#include <algorithm>
#include <cmath>
#include <type_traits>
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
  // t = 1 - phi / (s |z|) where positive, else 0 (no branch: where s |z| = 0
  // the quotient is inf or NaN, and max gives 0 for both)
  const real t = std::max(real(0), 1 - phi / (s * nz));
  // contact where lambda - s (u_z + g) > 0, and on the kink (= 0) if asked
  const real c = x4 - s * x3;
  // (the kink as a bitwise term: a choice between two comparisons is one
  // GCC 12 does not vectorise)
  return {t * z1, t * z2, std::max(real(0), c), t == 0, bool((c > 0) | (kink_contact & (c == 0)))};
}
}  // namespace

StateCounts count_states(index p, const std::uint8_t* status) {
  // three counts where the status lives (each a deterministic sum)
  auto count = [=](ContactState which) {
    return index(sum_over_entries("count states", p, Cost{1, 1},
                                  [=](index i) { return real(contact_state(status[i]) == which); }));
  };
  StateCounts c;
  c.separated = count(ContactState::separated);
  c.stick = count(ContactState::stick);
  c.slip = count(ContactState::slip);
  return c;
}

void coulomb_bound(index p, real F, const real* lambda, real* phi) {
  for_each_entry("coulomb bound", p, Cost{16, 2}, [=](index i) { phi[i] = F * (lambda[i] > 0 ? lambda[i] : real(0)); });
}

ResidualNorms approximation_step(index p, const ContactLaw& law, const real* scale, const real* units, const real* u,
                                 const real* lambda, const real* r, real* v, real* w, real* d, std::uint8_t* status) {
  TRESCA_ASSERT(p >= 0 && (p == 0 || (law.phi != nullptr && law.gap != nullptr)));
  // per-node work in parallel, then the deterministic blocked sum of v.v.
  // The three steps (s = 1, the units' s, the scale's s) are taken at every
  // node, also where two coincide (a missing units or scale is s = 1), and
  // whether units and scale are given is a compile-time choice of the body:
  // a branch in the body would keep its loop out of the CPU's vectors (a
  // conditional load), and a step chosen by a branch is a local struct that
  // GCC 12's nvptx backend cannot place in a warp's lanes (an internal
  // compiler error in make_decl_rtl). This file is compiled without
  // floating-point contraction (CMakeLists.txt): GCC fuses the vectorised
  // loop's multiply-adds differently from its scalar remainder's, and where
  // the threads' shares cut the loop would then change a node's last bits
  // with the thread count. (Oracles: the closed forms and the thread counts
  // in tests/test_newton.cpp, ApproximationStep; the dense reference Newton
  // there.)
  auto sweep = [&](auto has_units, auto has_scale) {
    // vector loop (tests/check_vectorised.py)
    for_each_entry("approximation step", p, kApproximationStepCost, [=](index i) {
      // x3 enters through F_4 = u_z + g
      const real x1 = u[i], x2 = u[p + i], x3 = u[2 * p + i] + law.gap[i], x4 = lambda[i];
      const real r1 = r[i], r2 = r[p + i];
      const real su = has_units ? units[i] : 1, ss = has_scale ? scale[i] : 1;
      const NodeStep paper = node_step(1, law.phi[i], x1, x2, x3, x4, r1, r2, law.kink_contact);
      const NodeStep unit = node_step(su, law.phi[i], x1, x2, x3, x4, r1, r2, law.kink_contact);
      const NodeStep step = node_step(ss, law.phi[i], x1, x2, x3, x4, r1, r2, law.kink_contact);
      v[i] = paper.d1 - x1;
      v[p + i] = paper.d2 - x2;
      v[2 * p + i] = -(r[2 * p + i] - x4);
      v[3 * p + i] = paper.d4 - x4;
      w[i] = su * (unit.d1 - x1);
      w[p + i] = su * (unit.d2 - x2);
      w[2 * p + i] = v[2 * p + i];
      w[3 * p + i] = unit.d4 - x4;
      d[i] = step.d1;
      d[p + i] = step.d2;
      d[2 * p + i] = step.d4;
      status[i] = std::uint8_t((step.contact ? kContact : 0) | (step.stick ? kStick : 0));
    });
  };
  using yes = std::true_type;
  using no = std::false_type;
  if (units && scale)
    sweep(yes{}, yes{});
  else if (units)
    sweep(yes{}, no{});
  else if (scale)
    sweep(no{}, yes{});
  else
    sweep(no{}, no{});
  return {dot(4 * p, v, v), dot(4 * p, w, w)};
}

}  // namespace tresca
