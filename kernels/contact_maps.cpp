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

// The approximation step at scale s (contact_maps.hpp) scales z = x_12 -
// r_12 / s by t = max(0, 1 - phi / (s |z|)): d_12 = t z, the node sticks
// where t = 0 (no branch: where s |z| = 0 the quotient is inf or NaN, and
// max0 gives 0 for both). Its d_4 = max(0, c) and its contact (c > 0, and
// c = 0 on the kink if asked) come from c = lambda - s (u_z + g). Each a
// scalar returned by value: no local of a device body has its address taken.
inline real step_factor(real s, real phi, real z1, real z2) {
  return max0(1 - phi / (s * std::sqrt(z1 * z1 + z2 * z2)));
}
// a node's envelope term e(u, r) (contact_maps.hpp: envelope_change) at
// stiffness s, bound phi and gap g, from its minimiser y: each a scalar
inline real envelope_term(real s, real phi, real g, real u1, real u2, real u3, real r1, real r2, real r3) {
  const real z1 = u1 - r1 / s, z2 = u2 - r2 / s;
  const real t = step_factor(s, phi, z1, z2);
  const real e1 = t * z1 - u1, e2 = t * z2 - u2;
  const real e3 = max0(u3 + g - r3 / s) - (u3 + g);  // y_z − u_z
  return r1 * e1 + r2 * e2 + r3 * e3 + real(0.5) * s * (e1 * e1 + e2 * e2 + e3 * e3) +
         phi * t * std::sqrt(z1 * z1 + z2 * z2);
}
inline bool in_contact(real c, bool kink_contact) {
  // (the kink as a bitwise term: a choice between two comparisons is one
  // GCC 12 does not vectorise)
  return bool((c > 0) | (kink_contact & (c == 0)));
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

EnvelopeChange envelope_change(index p, const ContactLaw& law, const real* scale, real a, const real* u, const real* r,
                               const real* du, const real* Sdu) {
  TRESCA_ASSERT(p >= 0 && (p == 0 || (law.phi != nullptr && law.gap != nullptr && scale != nullptr)));
  // a node's term at u + b du, r + b S du (b = 0: at u itself), returned by
  // value (no local of a device body has its address taken, above); the
  // law's two arrays taken, not the law (its bool's padding is stale stack
  // in the body's copy, which the device guard reads, §0zr)
  const real* phi = law.phi;
  const real* gap = law.gap;
  auto term = [=](index i, real b) {
    return envelope_term(scale[i], phi[i], gap[i], u[i] + b * du[i], u[p + i] + b * du[p + i],
                         u[2 * p + i] + b * du[2 * p + i], r[i] + b * Sdu[i], r[p + i] + b * Sdu[p + i],
                         r[2 * p + i] + b * Sdu[2 * p + i]);
  };
  EnvelopeChange e;
  e.change = sum_over_entries("envelope change", p, kEnvelopeChangeCost, [=](index i) { return term(i, a) - term(i, 0); });
  e.size = sum_over_entries("envelope size", p, kEnvelopeChangeCost,
                            [=](index i) { return std::abs(term(i, a)) + std::abs(term(i, 0)); });
  return e;
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
  auto sweep = [&](auto units_tag, auto scale_tag) {
    // (the choice as constants, not the tags: a tag captured in the body
    // is a byte and seven of stale stack, which the device guard read as a
    // host heap address, RESULTS.md §0zr)
    constexpr bool has_units = decltype(units_tag)::value, has_scale = decltype(scale_tag)::value;
    // vector loop (tests/check_vectorised.py)
    for_each_entry("approximation step", p, kApproximationStepCost, [=](index i) {
      // x3 enters through F_4 = u_z + g
      const real x1 = u[i], x2 = u[p + i], x3 = u[2 * p + i] + law.gap[i], x4 = lambda[i];
      const real r1 = r[i], r2 = r[p + i];
      const real su = has_units ? units[i] : 1, ss = has_scale ? scale[i] : 1;
      // the paper's step (s = 1), the units' (su) and the scale's (ss)
      const real pz1 = x1 - r1 / 1, pz2 = x2 - r2 / 1, uz1 = x1 - r1 / su, uz2 = x2 - r2 / su;
      const real sz1 = x1 - r1 / ss, sz2 = x2 - r2 / ss, phi = law.phi[i];
      const real tp = step_factor(1, phi, pz1, pz2), tu = step_factor(su, phi, uz1, uz2);
      const real ts = step_factor(ss, phi, sz1, sz2);
      const real cp = x4 - 1 * x3, cu = x4 - su * x3, cs = x4 - ss * x3;
      v[i] = tp * pz1 - x1;
      v[p + i] = tp * pz2 - x2;
      v[2 * p + i] = -(r[2 * p + i] - x4);
      v[3 * p + i] = max0(cp) - x4;
      w[i] = su * (tu * uz1 - x1);
      w[p + i] = su * (tu * uz2 - x2);
      w[2 * p + i] = v[2 * p + i];
      w[3 * p + i] = max0(cu) - x4;
      d[i] = ts * sz1;
      d[p + i] = ts * sz2;
      d[2 * p + i] = max0(cs);
      status[i] = std::uint8_t((in_contact(cs, law.kink_contact) ? kContact : 0) | (ts == 0 ? kStick : 0));
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
