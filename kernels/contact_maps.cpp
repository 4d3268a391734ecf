#include "contact_maps.hpp"

#include <algorithm>
#include <cmath>
#include <type_traits>
#include <vector>

#include "launch.hpp"
#include "vector_ops.hpp"

namespace tresca {

namespace {
// max(0, x) as std::max(real(0), x) computes it (0 where x is NaN), by
// value: std::max binds its arguments to references, and a launch body's
// temporaries whose address a call takes are, in GCC 12's GPU code, copies
// on the lanes' private stack whose reads it can get wrong (the step's t and
// d_4 read as 0: RESULTS.md §0zg; tests/check_device_code.py keeps every
// device body off that stack).
inline real max0(real x) { return real(0) < x ? x : real(0); }

// d_12, d_4 of the approximation step at scale s (contact_maps.hpp), and
// the node's state there
inline void node_step(real s, real phi, real x1, real x2, real x3, real x4, real r1, real r2, bool kink_contact,
                      real& d1, real& d2, real& d4, bool& stick, bool& contact) {
  const real z1 = x1 - r1 / s, z2 = x2 - r2 / s;
  const real nz = std::sqrt(z1 * z1 + z2 * z2);
  // t = 1 - phi / (s |z|) where positive, else 0 (no branch: where s |z| = 0
  // the quotient is inf or NaN, and max gives 0 for both)
  const real t = max0(1 - phi / (s * nz));
  // contact where lambda - s (u_z + g) > 0, and on the kink (= 0) if asked
  const real c = x4 - s * x3;
  d1 = t * z1;
  d2 = t * z2;
  d4 = max0(c);
  stick = t == 0;
  // (the kink as a bitwise term: a choice between two comparisons is one
  // GCC 12 does not vectorise)
  contact = bool((c > 0) | (kink_contact & (c == 0)));
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
      // the paper's step (s = 1), the units' and the scale's
      real p1, p2, p4, u1, u2, u4, s1, s2, s4;
      bool stick, contact, unused_stick, unused_contact;
      node_step(1, law.phi[i], x1, x2, x3, x4, r1, r2, law.kink_contact, p1, p2, p4, unused_stick, unused_contact);
      node_step(su, law.phi[i], x1, x2, x3, x4, r1, r2, law.kink_contact, u1, u2, u4, unused_stick, unused_contact);
      node_step(ss, law.phi[i], x1, x2, x3, x4, r1, r2, law.kink_contact, s1, s2, s4, stick, contact);
      v[i] = p1 - x1;
      v[p + i] = p2 - x2;
      v[2 * p + i] = -(r[2 * p + i] - x4);
      v[3 * p + i] = p4 - x4;
      w[i] = su * (u1 - x1);
      w[p + i] = su * (u2 - x2);
      w[2 * p + i] = v[2 * p + i];
      w[3 * p + i] = u4 - x4;
      d[i] = s1;
      d[p + i] = s2;
      d[2 * p + i] = s4;
      status[i] = std::uint8_t((contact ? kContact : 0) | (stick ? kStick : 0));
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
