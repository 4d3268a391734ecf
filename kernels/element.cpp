#include "element.hpp"

#include <cmath>

namespace tresca {

Lame lame_from(real E, real nu) {
  return {E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))};
}

void brick_stiffness(real hx, real hy, real hz, real E, real nu, real* Ke) {
  const Lame m = lame_from(E, nu);
  const real h[3] = {hx, hy, hz};
  const real gp[2] = {-1 / std::sqrt(real(3)), 1 / std::sqrt(real(3))};
  const real detJ = hx * hy * hz / 8;  // Gauss weights are 1
  for (int i = 0; i < 576; ++i) Ke[i] = 0;
  for (int g = 0; g < 8; ++g) {
    const real xi[3] = {gp[g & 1], gp[(g >> 1) & 1], gp[(g >> 2) & 1]};
    real dN[8][3];  // physical gradients of the 8 shape functions
    for (int L = 0; L < 8; ++L) {
      const real s[3] = {(L & 1) ? 1.0 : -1.0, (L & 2) ? 1.0 : -1.0, (L & 4) ? 1.0 : -1.0};
      for (int d = 0; d < 3; ++d) {
        real v = s[d] / 8;
        for (int e = 0; e < 3; ++e)
          if (e != d) v *= (1 + s[e] * xi[e]);
        dN[L][d] = v * 2 / h[d];
      }
    }
    // B (6x24)
    real B[6][24] = {};
    for (int L = 0; L < 8; ++L) {
      const real* g3 = dN[L];
      B[0][3 * L + 0] = g3[0];
      B[1][3 * L + 1] = g3[1];
      B[2][3 * L + 2] = g3[2];
      B[3][3 * L + 0] = g3[1];
      B[3][3 * L + 1] = g3[0];
      B[4][3 * L + 1] = g3[2];
      B[4][3 * L + 2] = g3[1];
      B[5][3 * L + 0] = g3[2];
      B[5][3 * L + 2] = g3[0];
    }
    real D[6][6] = {};
    for (int a = 0; a < 3; ++a) {
      for (int b = 0; b < 3; ++b) D[a][b] = m.lambda;
      D[a][a] += 2 * m.mu;
      D[3 + a][3 + a] = m.mu;
    }
    real DB[6][24];
    for (int a = 0; a < 6; ++a)
      for (int j = 0; j < 24; ++j) {
        real s = 0;
        for (int b = 0; b < 6; ++b) s += D[a][b] * B[b][j];
        DB[a][j] = s;
      }
    for (int i = 0; i < 24; ++i)
      for (int j = 0; j < 24; ++j) {
        real s = 0;
        for (int a = 0; a < 6; ++a) s += B[a][i] * DB[a][j];
        Ke[24 * i + j] += s * detJ;
      }
  }
}

void centroid_stress(real hx, real hy, real hz, real E, real nu, const real* ue, real* s) {
  // g[a][d] = d u_a / d x_d at the centroid
  real g[3][3] = {};
  const real h[3] = {hx, hy, hz};
  for (int L = 0; L < 8; ++L)
    for (int d = 0; d < 3; ++d) {
      const real sign = ((L >> d) & 1) ? 1 : -1;
      for (int a = 0; a < 3; ++a) g[a][d] += sign * ue[3 * L + a] / (4 * h[d]);
    }
  const Lame m = lame_from(E, nu);
  const real tr = g[0][0] + g[1][1] + g[2][2];
  for (int a = 0; a < 3; ++a) s[a] = m.lambda * tr + 2 * m.mu * g[a][a];
  s[3] = m.mu * (g[0][1] + g[1][0]);
  s[4] = m.mu * (g[1][2] + g[2][1]);
  s[5] = m.mu * (g[0][2] + g[2][0]);
}

real von_mises(const real* s) {
  const real dxy = s[0] - s[1], dyz = s[1] - s[2], dzx = s[2] - s[0];
  return std::sqrt(0.5 * (dxy * dxy + dyz * dyz + dzx * dzx) + 3 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5]));
}

}  // namespace tresca
