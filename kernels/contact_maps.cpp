#include "contact_maps.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "vector_ops.hpp"

namespace tresca {

namespace {
inline real node_step(index i, index p, real phi, real gap, const real* u, const real* lambda, const real* r, real* v,
                      real* d, std::uint8_t* status) {
  // x3 enters through F_4 = u_z + g
  const real x1 = u[i], x2 = u[p + i], x3 = u[2 * p + i] + gap, x4 = lambda[i];
  const real z1 = x1 - r[i], z2 = x2 - r[p + i];
  const real nz = std::sqrt(z1 * z1 + z2 * z2);
  const real s = nz > phi ? 1 - phi / nz : 0;
  const real d1 = s * z1, d2 = s * z2, d4 = std::max(real(0), x4 - x3);
  const real v1 = d1 - x1, v2 = d2 - x2, v3 = -(r[2 * p + i] - x4), v4 = d4 - x4;
  v[i] = v1;
  v[p + i] = v2;
  v[2 * p + i] = v3;
  v[3 * p + i] = v4;
  d[i] = d1;
  d[p + i] = d2;
  d[2 * p + i] = d4;
  status[i] = std::uint8_t((d4 > 0 ? kContact : 0) | (s == 0 ? kStick : 0));
  return v1 * v1 + v2 * v2 + v3 * v3 + v4 * v4;
}
}  // namespace

real approximation_step(index p, const ContactLaw& law, const real* u, const real* lambda, const real* r, real* v,
                        real* d, std::uint8_t* status) {
  TRESCA_ASSERT(p >= 0 && (p == 0 || (law.phi != nullptr && law.gap != nullptr)));
  // per-node work in parallel, then the deterministic blocked sum of v.v.
  // (The test oracle is the dense reference Newton in tests/test_newton.cpp.)
#pragma omp parallel for schedule(static) if (worth_threads(double(p) * kApproximationStepCost))
  for (index i = 0; i < p; ++i) node_step(i, p, law.phi[i], law.gap[i], u, lambda, r, v, d, status);
  return dot(4 * p, v, v);
}

}  // namespace tresca
