#include "core/contact/nested.hpp"

#include <algorithm>
#include <cmath>

namespace tresca {

ProblemSpec coarser_spec(const ProblemSpec& s) {
  ProblemSpec c = s;
  c.level = -1;
  c.ex = (s.ex + 1) / 2;
  c.ey = (s.ey + 1) / 2;
  c.ez = (s.ez + 1) / 2;
  return c;
}

bool has_coarser(const ProblemSpec& s, index min_contact_nodes) {
  const ProblemSpec c = coarser_spec(s);
  return c.ex < s.ex && c.ex >= 2 && c.contact_nodes() >= min_contact_nodes;
}

real contact_area(const GridDims& g, index c) {
  const index ix = 1 + c % g.ex, iy = c / g.ex;
  const real ax = ix == g.ex ? 0.5 : 1, ay = (iy == 0 || iy == g.ey) ? 0.5 : 1;
  return ax * ay * g.hx() * g.hy();
}

namespace {

index contact_nodes(const GridDims& g) { return g.ex * g.ny(); }

// contact node of the bottom-face node (ix >= 1, iy)
index contact_index(const GridDims& g, index ix, index iy) { return (ix - 1) + g.ex * iy; }

// bilinear interpolation at (x, y) of a field given on the bottom-face nodes
// (nx * ny values, x-fastest)
real bilinear(const GridDims& g, const std::vector<real>& f, real x, real y) {
  const real sx = std::clamp((x - g.x0) / g.hx(), real(0), real(g.ex)), sy = std::clamp((y - g.y0) / g.hy(), real(0), real(g.ey));
  const index ix = std::min(index(sx), g.ex - 1), iy = std::min(index(sy), g.ey - 1);
  const real tx = sx - real(ix), ty = sy - real(iy);
  const index n = g.nx();
  return (1 - tx) * (1 - ty) * f[ix + n * iy] + tx * (1 - ty) * f[ix + 1 + n * iy] + (1 - tx) * ty * f[ix + n * (iy + 1)] +
         tx * ty * f[ix + 1 + n * (iy + 1)];
}

}  // namespace

ContactConditions coarse_conditions(const GridDims& gf, const ContactConditions& f, const GridDims& gc) {
  const index pc = contact_nodes(gc);
  ContactConditions c{std::vector<real>(pc), std::vector<real>(pc)};
  for (index j = 0; j < pc; ++j) {
    const auto [x, y] = contact_position(gc, j);
    const index ix = std::clamp(index(std::lround((x - gf.x0) / gf.hx())), index(1), gf.ex);
    const index iy = std::clamp(index(std::lround((y - gf.y0) / gf.hy())), index(0), gf.ey);
    const index i = contact_index(gf, ix, iy);
    c.phi[j] = f.phi[i] / contact_area(gf, i) * contact_area(gc, j);
    c.gap[j] = f.gap[i];
  }
  return c;
}

void prolongate_contact(const GridDims& gc, const std::vector<real>& uc, const std::vector<real>& lc,
                        const GridDims& gf, std::vector<real>& uf, std::vector<real>& lf) {
  const index pc = contact_nodes(gc), pf = contact_nodes(gf), M = gc.nx() * gc.ny();
  // coarse fields on the whole bottom face: u = 0 on x = 0, the pressure
  // there continued from x = hx
  std::vector<real> face[4];
  for (auto& f : face) f.assign(M, 0);
  for (index j = 0; j < pc; ++j) {
    const index ix = 1 + j % gc.ex, iy = j / gc.ex, n = ix + gc.nx() * iy;
    for (int a = 0; a < 3; ++a) face[a][n] = uc[a * pc + j];
    face[3][n] = lc[j] / contact_area(gc, j);
    if (ix == 1) face[3][gc.nx() * iy] = face[3][n];
  }
  uf.assign(3 * pf, 0);
  lf.assign(pf, 0);
  for (index i = 0; i < pf; ++i) {
    const auto [x, y] = contact_position(gf, i);
    for (int a = 0; a < 3; ++a) uf[a * pf + i] = bilinear(gc, face[a], x, y);
    lf[i] = std::max(real(0), bilinear(gc, face[3], x, y)) * contact_area(gf, i);
  }
}

}  // namespace tresca
