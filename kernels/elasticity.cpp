#include "elasticity.hpp"

#include <algorithm>
#include <cmath>
#include <type_traits>

#include "element.hpp"
#include "isa.hpp"
#include "launch.hpp"
#include "stencil_row.hpp"

namespace tresca {
namespace {

std::uint8_t axis_class(index i, index n, bool c_lo, bool c_hi) {
  auto constrained = [&](index j) { return (c_lo && j == 0) || (c_hi && j == n - 1); };
  std::uint8_t c = 0;
  if (i > 0) c |= kHasL;
  if (i < n - 1) c |= kHasR;
  if (i > 0 && constrained(i - 1)) c |= kDropL;
  if (i < n - 1 && constrained(i + 1)) c |= kDropR;
  if (constrained(i)) c |= kSelf;
  return c;
}

// Is the neighbour at offset d in {-1, 0, 1} along one axis a constrained
// node (its coupling is dropped) for a node of class c?
bool dropped(std::uint8_t c, int d) { return (d < 0 && (c & kDropL)) || (d > 0 && (c & kDropR)); }

}  // namespace

ElasticityStencil build_elasticity_stencil(const GridDims& g, unsigned faces, real E, real nu) {
  return build_elasticity_stencil(g, faces, E, nu, {g.hx(), g.hy(), g.hz()});
}

ElasticityStencil build_elasticity_stencil(const GridDims& g, unsigned faces, real E, real nu,
                                           const std::array<real, 3>& h) {
  HostLaunches host;  // built entry by entry, then moved where launches run
  ElasticityStencil k;
  k.g = g;
  k.faces = faces;
  k.E = E;
  k.nu = nu;
  brick_stiffness(h[0], h[1], h[2], E, nu, k.Ke.data());
  const index n[3] = {g.nx(), g.ny(), g.nz()};
  const bool lo[3] = {bool(faces & kFaceX0), bool(faces & kFaceY0), bool(faces & kFaceZ0)};
  const bool hi[3] = {bool(faces & kFaceX1), bool(faces & kFaceY1), bool(faces & kFaceZ1)};
  for (int ax = 0; ax < 3; ++ax) {
    k.cls[ax].resize(n[ax]);
    for (index i = 0; i < n[ax]; ++i) k.cls[ax][i] = axis_class(i, n[ax], lo[ax], hi[ax]);
  }
  for (index i = 0; i < n[0]; ++i)
    if (i == 0 || k.cls[0][i] != k.cls[0][i - 1]) k.run_begin.push_back(i);
  k.run_begin.push_back(n[0]);

  const index N = g.nodes();
  k.slot.assign(32 * 32 * 32, -1);
  k.first.push_back(0);
  auto distinct = [](const Field<std::uint8_t>& v) {
    std::vector<std::uint8_t> u(v.begin(), v.end());
    std::sort(u.begin(), u.end());
    u.erase(std::unique(u.begin(), u.end()), u.end());
    return u;
  };
  for (std::uint8_t cx : distinct(k.cls[0]))
    for (std::uint8_t cy : distinct(k.cls[1]))
      for (std::uint8_t cz : distinct(k.cls[2])) {
        const std::uint8_t c[3] = {cx, cy, cz};
        // dense 27x3x3 stencil from the element matrices around the node
        real S[27][3][3] = {};
        for (int side = 0; side < 8; ++side) {  // side bit ax: 0 = element on the left, 1 = right
          bool present = true;
          int lnode[3];
          for (int ax = 0; ax < 3; ++ax) {
            const bool right = (side >> ax) & 1;
            present = present && (right ? (c[ax] & kHasR) : (c[ax] & kHasL));
            lnode[ax] = right ? 0 : 1;
          }
          if (!present) continue;
          const int L = lnode[0] + 2 * lnode[1] + 4 * lnode[2];
          for (int M = 0; M < 8; ++M) {
            const int d[3] = {(M & 1) - lnode[0], ((M >> 1) & 1) - lnode[1], ((M >> 2) & 1) - lnode[2]};
            if (dropped(cx, d[0]) || dropped(cy, d[1]) || dropped(cz, d[2])) continue;
            const int di = (d[0] + 1) + 3 * (d[1] + 1) + 9 * (d[2] + 1);
            for (int a = 0; a < 3; ++a)
              for (int b = 0; b < 3; ++b) S[di][a][b] += k.Ke[24 * (3 * L + a) + 3 * M + b];
          }
        }
        const std::int32_t s = std::int32_t(k.first.size() - 1) / 7;
        k.slot[(cx * 32 + cy) * 32 + cz] = s;
        real scale = 0;
        for (int a = 0; a < 3; ++a) scale = std::max(scale, std::abs(S[13][a][a]));
        std::vector<StencilGroup> by_mask[8];
        for (int di = 0; di < 27; ++di) {
          const index dx = di % 3 - 1, dy = (di / 3) % 3 - 1, dz = di / 9 - 1;
          for (int b = 0; b < 3; ++b) {
            StencilGroup grp{b * N + dx + g.nx() * (dy + g.ny() * dz), {0, 0, 0}};
            int mask = 0;
            for (int a = 0; a < 3; ++a)
              // exact cancellations leave round-off of order 1e-16*scale
              if (std::abs(S[di][a][b]) > 1e-12 * scale) {
                grp.c[a] = S[di][a][b];
                mask |= 1 << a;
              }
            if (mask) by_mask[mask].push_back(grp);
          }
        }
        for (int m = 1; m < 8; ++m) {
          for (const StencilGroup& q : by_mask[m]) k.groups.push_back(q);
          k.first.push_back(std::int32_t(k.groups.size()));
        }
        for (int a = 0; a < 3; ++a) {
          k.center.push_back(S[13][a][a]);
          k.inv_center.push_back(1 / S[13][a][a]);
        }
      }
  k.move_to(host.space_before());
  return k;
}

template <class T>
ElasticityStencilT<T> stencil_in_precision(const ElasticityStencil& kk) {
  HostLaunches host;
  ElasticityStencil k = kk;
  k.move_to(Space::host);
  ElasticityStencilT<T> t;
  t.g = k.g;
  t.faces = k.faces;
  t.E = k.E;
  t.nu = k.nu;
  t.Ke = k.Ke;
  for (int a = 0; a < 3; ++a) t.cls[a] = k.cls[a];
  t.run_begin = k.run_begin;
  t.slot = k.slot;
  t.first = k.first;
  for (const StencilGroup& q : k.groups) t.groups.push_back({q.off, {T(q.c[0]), T(q.c[1]), T(q.c[2])}});
  for (real c : k.center) {
    t.center.push_back(T(c));
    t.inv_center.push_back(T(1 / c));  // (as the multigrid's dinv: 1 / diag in double, rounded to T)
  }
  t.move_to(host.space_before());
  return t;
}
template ElasticityStencilT<float> stencil_in_precision<float>(const ElasticityStencil&);
template ElasticityStencilT<double> stencil_in_precision<double>(const ElasticityStencil&);

template <class T>
StencilView<T> view(const ElasticityStencilT<T>& k) {
  return StencilView<T>{k.g,          {k.cls[0].data(), k.cls[1].data(), k.cls[2].data()},
                        k.run_begin.data(), index(k.run_begin.size()) - 1,
                        k.slot.data(), k.first.data(), k.groups.data(), k.inv_center.data()};
}
template StencilView<double> view(const ElasticityStencilT<double>&);
template StencilView<float> view(const ElasticityStencilT<float>&);

template <class T>
void elasticity_apply(const ElasticityStencilT<T>& k, const T* x, const ApplyOut<T>& out, const RowBlock& rows) {
  const GridDims& g = k.g;
  const index nx = g.nx();
  TRESCA_ASSERT(0 <= rows.z_begin && rows.z_begin <= rows.z_end && rows.z_end <= g.nz());
  TRESCA_ASSERT(0 <= rows.y_begin && rows.y_begin <= rows.y_end && rows.y_end <= g.ny());
  // y is written while x and b are read (and x read at entries other than those written)
  TRESCA_ASSERT(x != out.y && (out.b == nullptr || out.b != out.y));
  TRESCA_ASSERT(!k.groups.empty());
  if (launch_on_device()) return elasticity_apply_rows(view(k), x, out, rows);  // the device's form
  // Each thread its share of the rows (the nodes it owns in every kernel,
  // launch.hpp), swept in bands of about kBand x-rows through its planes, so
  // that the three input planes of a band (3 x (kBand+2) rows) stay in L2.
  constexpr index kBand = 16;
  const index rows_y = rows.y_end - rows.y_begin, rows_z = rows.z_end - rows.z_begin;
  const double nodes = double(nx) * double(rows_y) * double(rows_z);
  const StencilView<T> v = view(k);
  // each band's arithmetic in the instruction set chosen at start (isa.hpp)
  const auto apply_band = isa_apply_band<T>(isa());
  const char* name = precision_name<T>("apply", "apply (float)");
  for_each_host_share(name, rows_y * rows_z, nodes * in_precision<T>(apply_cost(out)), [=](Share s) {
    for_each_row_band(rows, s, kBand, [&](const RowBlock& b) { apply_band(v, x, out, b); });
  });
}
template void elasticity_apply<double>(const ElasticityStencilT<double>&, const double*, const ApplyOut<double>&,
                                       const RowBlock&);
template void elasticity_apply<float>(const ElasticityStencilT<float>&, const float*, const ApplyOut<float>&,
                                      const RowBlock&);

template <class T>
void elasticity_apply(const ElasticityStencilT<T>& k, const T* x, T* y, const RowBlock& rows, const T* b) {
  elasticity_apply(k, x, b ? residual_out(b, y) : operator_out(y), rows);
}
template void elasticity_apply<double>(const ElasticityStencilT<double>&, const double*, double*, const RowBlock&,
                                       const double*);
template void elasticity_apply<float>(const ElasticityStencilT<float>&, const float*, float*, const RowBlock&,
                                      const float*);

template <class T>
void elasticity_apply_rows(const StencilView<T>& k, const T* x, const ApplyOut<T>& out, const RowBlock& rows) {
  const index nx = k.g.nx(), ny = k.g.ny(), N = k.g.nodes();
  TRESCA_ASSERT(0 <= rows.z_begin && rows.z_begin <= rows.z_end && rows.z_end <= k.g.nz());
  TRESCA_ASSERT(0 <= rows.y_begin && rows.y_begin <= rows.y_end && rows.y_end <= ny);
  TRESCA_ASSERT(x != out.y && (out.b == nullptr || out.b != out.y));
  const index z0 = rows.z_begin, y0 = rows.y_begin;
  const index nz = rows.z_end - rows.z_begin, nyr = rows.y_end - rows.y_begin;
  const double nodes = double(nx) * double(nz) * double(nyr);
  const char* name = precision_name<T>("apply", "apply (float)");  // (the banded apply's device form)
  // Its form (measured on an H200 against 3 groups a pass, a node a lane
  // and rows in runs: RESULTS.md §0zh, §0zi, §0zm), which keeps the order of
  // a node's sum, its groups as they are stored:
  //  - P groups a pass: a lane issues the loads of P groups before their
  //    multiply-adds, in one block of code that ptxas may schedule as a
  //    whole;
  //  - U nodes a lane: a lane computes U nodes of the run at once, S apart
  //    (for each of them the warp's lanes read neighbouring entries), and
  //    loads each group's offset and coefficients once for the U: U times
  //    the independent loads in flight, a U-th of the group loads. A run
  //    shorter than U warps (the one-node runs at a row's ends) is swept a
  //    node a lane; where U*S passes the run's end, a lane computes its
  //    first node again and stores nothing for the others. Four in float
  //    (1.48x one), one in double, whose values take twice the registers
  //    (four: 12 % slower than one).
  constexpr int P = 9, U = sizeof(T) == sizeof(float) ? 4 : 1;
  with_kind(out, [&](auto kind) {
    constexpr OutKind K = decltype(kind)::value;
    for_each_block(name, nz, nyr, nodes * in_precision<T>(apply_cost(out)), [=](index jz, index jy) {
      sweep_row<K>(k, nx, ny, N, z0 + jz, y0 + jy, x, out,
                   [&](const std::int32_t* f, const T* xr, index row, index i0, index i1, const T* dc) {
                     const StencilGroupT<T>*q0 = k.groups + f[0], *q1 = k.groups + f[7];
                     auto nodes_a_lane = [&](auto width) {
                       constexpr int W = decltype(width)::value;
                       const index S = (i1 - i0 + W - 1) / W;
#pragma omp simd
                       for (index j = 0; j < S; ++j) {
                         index at[W];
                         T acc[W][3];
#pragma GCC unroll 4
                         for (int u = 0; u < W; ++u) {
                           at[u] = i0 + j + u * S < i1 ? i0 + j + u * S : i0 + j;
                           acc[u][0] = acc[u][1] = acc[u][2] = 0;
                         }
                         auto add = [&](const StencilGroupT<T>& q) {
#pragma GCC unroll 4
                           for (int u = 0; u < W; ++u) {
                             const T v = xr[at[u] + q.off];
                             acc[u][0] += q.c[0] * v;
                             acc[u][1] += q.c[1] * v;
                             acc[u][2] += q.c[2] * v;
                           }
                         };
                         const StencilGroupT<T>* q = q0;
                         for (; q1 - q >= P; q += P) {
#pragma GCC unroll 9
                           for (int g = 0; g < P; ++g) add(q[g]);
                         }
                         for (; q != q1; ++q) add(*q);
#pragma GCC unroll 4
                         for (int u = 0; u < W; ++u)
                           if (u == 0 || i0 + j + u * S < i1) {
                             for (int a = 0; a < 3; ++a) {
                               const index jj = a * N + row + at[u];
                               put<K>(out, x, jj, acc[u][a], dinv_at<K, T>(out, dc, a, jj));
                             }
                           }
                       }
                     };
                     constexpr index kLanes = 32;  // a warp's (GCC's simd width on the GPU)
                     if (U > 1 && i1 - i0 >= kLanes * U) return nodes_a_lane(std::integral_constant<int, U>{});
                     nodes_a_lane(std::integral_constant<int, 1>{});
                   });
    });
  });
}

template void elasticity_apply_rows<double>(const StencilView<double>&, const double*, const ApplyOut<double>&,
                                            const RowBlock&);
template void elasticity_apply_rows<float>(const StencilView<float>&, const float*, const ApplyOut<float>&,
                                           const RowBlock&);

template <class T>
void elasticity_apply(const ElasticityStencilT<T>& k, const T* x, T* y, index z_begin, index z_end, const T* b) {
  elasticity_apply(k, x, y, RowBlock{z_begin, z_end, 0, k.g.ny()}, b);
}
template void elasticity_apply<double>(const ElasticityStencilT<double>&, const double*, double*, index, index,
                                       const double*);
template void elasticity_apply<float>(const ElasticityStencilT<float>&, const float*, float*, index, index,
                                      const float*);

void elasticity_apply_ref(const ElasticityStencil& k, const real* x, real* y, index z_begin, index z_end,
                          const real* b) {
  const GridDims& g = k.g;
  const index N = g.nodes();
  for (index iz = z_begin; iz < z_end; ++iz)
    for (index iy = 0; iy < g.ny(); ++iy)
      for (index ix = 0; ix < g.nx(); ++ix)
        for (int a = 0; a < 3; ++a) y[a * N + g.node(ix, iy, iz)] = 0;
  for (index ez = 0; ez < g.ez; ++ez)
    for (index ey = 0; ey < g.ey; ++ey)
      for (index ex = 0; ex < g.ex; ++ex) {
        index nodes[8];
        bool fixed[8];
        real xe[24], ye[24];
        for (int L = 0; L < 8; ++L) {
          const index ix = ex + (L & 1), iy = ey + ((L >> 1) & 1), iz = ez + ((L >> 2) & 1);
          nodes[L] = g.node(ix, iy, iz);
          fixed[L] = node_constrained(g, k.faces, ix, iy, iz) || iz < z_begin || iz >= z_end;
          const bool c = node_constrained(g, k.faces, ix, iy, iz);
          for (int a = 0; a < 3; ++a) xe[3 * L + a] = c ? 0 : x[a * N + nodes[L]];
        }
        for (int i = 0; i < 24; ++i) {
          real s = 0;
          for (int j = 0; j < 24; ++j) s += k.Ke[24 * i + j] * xe[j];
          ye[i] = s;
        }
        for (int L = 0; L < 8; ++L)
          if (!fixed[L])
            for (int a = 0; a < 3; ++a) y[a * N + nodes[L]] += ye[3 * L + a];
      }
  for (index iz = z_begin; iz < z_end; ++iz)
    for (index iy = 0; iy < g.ny(); ++iy)
      for (index ix = 0; ix < g.nx(); ++ix)
        for (int a = 0; a < 3; ++a) {
          const index j = a * N + g.node(ix, iy, iz);
          if (node_constrained(g, k.faces, ix, iy, iz)) y[j] = x[j];
          if (b) y[j] = b[j] - y[j];
        }
}

void elasticity_diagonal(const ElasticityStencil& k, real* d) {
  const StencilView<real> v = view(k);
  const real* center = k.center.data();
  const GridDims g = k.g;
  const index nx = g.nx(), N = g.nodes();
  for_each_block("diagonal", g.nz(), g.ny(), double(N) * kDiagonalCost, [=](index iz, index iy) {
    const std::uint8_t cy = v.cls[1][iy], cz = v.cls[2][iz];
    TRESCA_DEVICE_LANES  // (reads slot and center through indices)
    for (index ix = 0; ix < nx; ++ix) {
      const std::uint8_t cx = v.cls[0][ix];
      const index n = ix + nx * (iy + g.ny() * iz);
      const bool fixed = (cx | cy | cz) & kSelf;
      const std::int32_t s = fixed ? -1 : v.slot[(cx * 32 + cy) * 32 + cz];
      for (int a = 0; a < 3; ++a) d[a * N + n] = fixed ? 1 : center[3 * s + a];
    }
  });
}

void elasticity_diagonal_ref(const ElasticityStencil& k, real* d) {
  const GridDims& g = k.g;
  const index N = g.nodes();
  for (index i = 0; i < 3 * N; ++i) d[i] = 0;
  for (index ez = 0; ez < g.ez; ++ez)
    for (index ey = 0; ey < g.ey; ++ey)
      for (index ex = 0; ex < g.ex; ++ex)
        for (int L = 0; L < 8; ++L) {
          const index n = g.node(ex + (L & 1), ey + ((L >> 1) & 1), ez + ((L >> 2) & 1));
          for (int a = 0; a < 3; ++a) d[a * N + n] += k.Ke[24 * (3 * L + a) + 3 * L + a];
        }
  for (index iz = 0; iz < g.nz(); ++iz)
    for (index iy = 0; iy < g.ny(); ++iy)
      for (index ix = 0; ix < g.nx(); ++ix)
        if (node_constrained(g, k.faces, ix, iy, iz))
          for (int a = 0; a < 3; ++a) d[a * N + g.node(ix, iy, iz)] = 1;
}

template <class T>
void zero_constrained(const GridDims& g, unsigned faces, T* v) {
  // per node row: all of it on a constrained y or z face, else its ends on
  // constrained x faces (O(surface) work, one launch)
  const index nx = g.nx(), ny = g.ny(), nz = g.nz(), N = g.nodes();
  if (!faces) return;
  for_each_block("zero constrained", nz, ny, double(ny) * double(nz) * Cost{48, 0}, [=](index iz, index iy) {
    const ConstrainedRow c(g, faces, iy, iz);
    for (int a = 0; a < 3; ++a) {
      T* row = v + a * N + nx * (iy + ny * iz);
      if (c.whole) {
#pragma omp simd
        for (index ix = 0; ix < nx; ++ix) row[ix] = 0;
        continue;
      }
      if (c.x0) row[0] = 0;
      if (c.x1) row[nx - 1] = 0;
    }
  });
}

template void zero_constrained<double>(const GridDims&, unsigned, double*);
template void zero_constrained<float>(const GridDims&, unsigned, float*);

}  // namespace tresca
