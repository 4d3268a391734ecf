// The brick stiffness against an independent closed form: with full 2x2x2
// Gauss integration Ke is exact, and each entry factors into 1D integrals
//   Ke[(L,a),(M,b)] = lambda I(a,b) + mu I(b,a) + mu delta_ab sum_d I(d,d),
//   I(a,b) = ∫ d_a phi_L d_b phi_M = prod over axes of 1D mass/stiffness/mixed integrals.
#include <gtest/gtest.h>

#include <cmath>

#include "kernels/element.hpp"

namespace tresca {

namespace {
// ∫_0^h f_i g_j with f, g in {phi, phi'} ; i, j in {0,1}
real integral1d(real h, bool di, bool dj, int i, int j) {
  if (!di && !dj) return h / 6 * (i == j ? 2 : 1);
  if (di && dj) return (i == j ? 1 : -1) / h;
  const int k = di ? i : j;  // the differentiated one
  return (k == 0 ? -0.5 : 0.5);
}
}  // namespace

TEST(BrickStiffness, MatchesClosedFormOnAnisotropicBrick) {
  const real h[3] = {0.3, 0.7, 1.1}, E = 2.1e9, nu = 0.277;
  real Ke[576];
  brick_stiffness(h[0], h[1], h[2], E, nu, Ke);
  const Lame m = lame_from(E, nu);
  auto I = [&](int L, int M, int a, int b) {
    real v = 1;
    for (int d = 0; d < 3; ++d)
      v *= integral1d(h[d], d == a, d == b, (L >> d) & 1, (M >> d) & 1);
    return v;
  };
  real maxerr = 0, scale = 0;
  for (int L = 0; L < 8; ++L)
    for (int M = 0; M < 8; ++M)
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) {
          real ref = m.lambda * I(L, M, a, b) + m.mu * I(L, M, b, a);
          if (a == b)
            for (int d = 0; d < 3; ++d) ref += m.mu * I(L, M, d, d);
          maxerr = std::max(maxerr, std::abs(Ke[24 * (3 * L + a) + 3 * M + b] - ref));
          scale = std::max(scale, std::abs(ref));
        }
  EXPECT_LT(maxerr, 1e-13 * scale);
}

TEST(BrickStiffness, IsSymmetricWithSixRigidModesInKernel) {
  real Ke[576];
  brick_stiffness(0.5, 0.25, 0.45, 1.0, 0.3, Ke);
  for (int i = 0; i < 24; ++i)
    for (int j = 0; j < 24; ++j) EXPECT_NEAR(Ke[24 * i + j], Ke[24 * j + i], 1e-15);
  for (int mode = 0; mode < 6; ++mode) {
    real u[24];
    for (int L = 0; L < 8; ++L) {
      const real x[3] = {0.5 * (L & 1), 0.25 * ((L >> 1) & 1), 0.45 * ((L >> 2) & 1)};
      for (int a = 0; a < 3; ++a) u[3 * L + a] = 0;
      if (mode < 3) {
        u[3 * L + mode] = 1;
      } else {  // rotation about axis mode-3: u = e_axis × x
        const int ax = mode - 3, p = (ax + 1) % 3, q = (ax + 2) % 3;
        u[3 * L + p] = -x[q];
        u[3 * L + q] = x[p];
      }
    }
    for (int i = 0; i < 24; ++i) {
      real s = 0;
      for (int j = 0; j < 24; ++j) s += Ke[24 * i + j] * u[j];
      EXPECT_NEAR(s, 0, 1e-14) << "mode " << mode << " row " << i;
    }
  }
}

}  // namespace tresca
