#include "transfer.hpp"

#include <algorithm>
#include <type_traits>

#include "launch.hpp"

namespace tresca {
namespace {

Interp1D build_axis(index ef, index ec) {
  Interp1D a;
  const index nf = ef + 1, nc = ec + 1;
  a.j0.resize(nf);
  a.w.resize(nf);
  for (index i = 0; i < nf; ++i) {
    // coarse coordinate of fine node i is t = i*ec/ef, computed exactly in integers
    index j = (i * ec) / ef;
    index rem = i * ec - j * ef;
    if (j >= ec) {  // the last node sits on the last coarse node
      j = ec - 1;
      rem = ef;
    }
    a.j0[i] = j;
    a.w[i] = real(rem) / real(ef);
  }
  std::vector<std::vector<std::pair<index, real>>> lists(nc);
  for (index i = 0; i < nf; ++i) {
    if (1 - a.w[i] != 0) lists[a.j0[i]].push_back({i, 1 - a.w[i]});
    if (a.w[i] != 0) lists[a.j0[i] + 1].push_back({i, a.w[i]});
  }
  a.tstart.push_back(0);
  for (index j = 0; j < nc; ++j) {
    for (auto& p : lists[j]) {
      a.tf.push_back(p.first);
      a.tw.push_back(p.second);
    }
    a.tstart.push_back(index(a.tf.size()));
  }
  bool halving = nf >= 2 * nc - 2;
  a.pair_w.resize(2 * nc + 2);
  for (index i = 0; i < nf && halving; ++i) {
    if (a.j0[i] == i / 2)
      a.pair_w[i + 2] = a.w[i];
    else  // (the last node as coarse node i/2, if that is its only one)
      halving = i == nf - 1 && a.j0[i] == i / 2 - 1 && a.w[i] == 1;
  }
  if (!halving) a.pair_w = Field<real>();
  return a;
}

// an axis's arrays as plain pointers (captured by value in the launches)
struct AxisView {
  const index *j0, *tstart, *tf;
  const real *w, *tw, *pw;  // pw: pair_w, pw[i] for i in [-2, 2 nc) (halving only)
  bool halving;
  explicit AxisView(const Interp1D& a)
      : j0(a.j0.data()),
        tstart(a.tstart.data()),
        tf(a.tf.data()),
        w(a.w.data()),
        tw(a.tw.data()),
        pw(a.halving() ? a.pair_w.data() + 2 : nullptr),
        halving(a.halving()) {}
};

}  // namespace

Transfer build_transfer(const GridDims& fine, const GridDims& coarse) {
  HostLaunches host;
  Transfer t;
  t.fine = fine;
  t.coarse = coarse;
  t.axis[0] = build_axis(fine.ex, coarse.ex);
  t.axis[1] = build_axis(fine.ey, coarse.ey);
  t.axis[2] = build_axis(fine.ez, coarse.ez);
  t.move_to(host.space_before());
  return t;
}

Transfer slice_rows(const Transfer& whole, index f0, index f1, index c0, index c1) {
  TRESCA_ASSERT(0 <= f0 && f0 + 2 <= f1 && f1 <= whole.fine.ny() && 0 <= c0 && c0 + 2 <= c1 && c1 <= whole.coarse.ny());
  HostLaunches host;
  Transfer t = whole;
  t.move_to(Space::host);
  Transfer s = t;
  s.fine = rows_box(t.fine, f0, f1);
  s.coarse = rows_box(t.coarse, c0, c1);
  const Interp1D& Y = t.axis[1];
  Interp1D y;
  for (index i = f0; i < f1; ++i) {
    // rows outside [c0, c1) are clamped in (their values are partial anyway)
    y.j0.push_back(std::clamp(Y.j0[i] - c0, index(0), c1 - c0 - 2));
    y.w.push_back(Y.w[i]);
  }
  y.tstart.push_back(0);
  for (index j = c0; j < c1; ++j) {
    for (index k = Y.tstart[j]; k < Y.tstart[j + 1]; ++k)
      if (Y.tf[k] >= f0 && Y.tf[k] < f1) {
        y.tf.push_back(Y.tf[k] - f0);
        y.tw.push_back(Y.tw[k]);
      }
    y.tstart.push_back(index(y.tf.size()));
  }
  s.axis[1] = std::move(y);
  s.move_to(host.space_before());
  return s;
}

template <class T>
void prolongate(const Transfer& t, int comps, const T* coarse, T* fine, const T* base, unsigned zero_faces) {
  TRESCA_ASSERT(comps >= 1 && comps <= 3 && index(t.axis[0].j0.size()) == t.fine.nx());
  // Per fine row (iy, iz): combine the 4 coarse rows of its y/z support into
  // one coarse-length row buffer (contiguous, vectorised), then interpolate
  // along x from that buffer (it sits in L1): 4 FMAs per coarse node plus
  // 2 per fine node, instead of 8 coarse reads per fine node. Along a
  // halving x axis fine nodes 2k and 2k+1 both lie between s[k] and s[k+1]:
  // a lane per pair, contiguous reads (the general axis reads s[j0[ix]],
  // which the CPU runs as scalar code).
  const GridDims &f = t.fine, &c = t.coarse;
  const index Nf = f.nodes(), Nc = c.nodes(), cnx = c.nx(), cny = c.ny(), fnx = f.nx();
  const index fny = f.ny();
  const AxisView X(t.axis[0]), Y(t.axis[1]), Z(t.axis[2]);
  // component a's fine row (iy, iz); s: a coarse row of the worker's own,
  // and one entry
  const auto fine_row = [=](index a, index iz, index iy, T* s) {
    // 0 on the faces in zero_faces, as a select per entry: on the device no
    // lane writes another lane's entry
    const ConstrainedRow m(f, zero_faces, iy, iz);
    const index jz = Z.j0[iz], jy = Y.j0[iy];
    const T wz = T(Z.w[iz]), wy = T(Y.w[iy]);
    const T w00 = (1 - wy) * (1 - wz), w10 = wy * (1 - wz), w01 = (1 - wy) * wz, w11 = wy * wz;
    const index b00 = cnx * (jy + cny * jz), b10 = b00 + cnx, b01 = b00 + cnx * cny, b11 = b01 + cnx;
    const T* u = coarse + a * Nc;
#pragma omp simd
    for (index j = 0; j < cnx; ++j) s[j] = w00 * u[b00 + j] + w10 * u[b10 + j] + w01 * u[b01 + j] + w11 * u[b11 + j];
    const index at = a * Nf + fnx * (iy + fny * iz);
    T* v = fine + at;
    const T* v0 = base ? base + at : nullptr;
    if (X.halving) {
      // the pairs, then a last node of its own where fnx is odd (a nested
      // axis's last fine node: weight 0 on s[cnx]); the base's test out of
      // the loop (a load under a condition keeps it from the vector units)
      s[cnx] = 0;
      const auto pairs = [&](auto with_base) {
#pragma omp simd  // vector loop (tests/check_vectorised.py)
        for (index k = 0; k < fnx / 2; ++k) {
          const index i = 2 * k;
          const T a0 = s[k], a1 = s[k + 1], w0 = T(X.pw[i]), w1 = T(X.pw[i + 1]);
          const T p0 = (with_base ? v0[i] : T(0)) + (1 - w0) * a0 + w0 * a1;
          const T p1 = (with_base ? v0[i + 1] : T(0)) + (1 - w1) * a0 + w1 * a1;
          v[i] = m.at(i) ? T(0) : p0;
          v[i + 1] = m.at(i + 1) ? T(0) : p1;
        }
      };
      if (v0)
        pairs(std::true_type());
      else
        pairs(std::false_type());
      if (fnx % 2) {
        const index i = fnx - 1, k = i / 2;
        const T wx = T(X.pw[i]);
        const T p = (v0 ? v0[i] : T(0)) + (1 - wx) * s[k] + wx * s[k + 1];
        v[i] = m.at(i) ? T(0) : p;
      }
      return;
    }
    TRESCA_DEVICE_LANES
    for (index ix = 0; ix < fnx; ++ix) {
      const index j = X.j0[ix];
      const T wx = T(X.w[ix]);
      const T p = (v0 ? v0[ix] : T(0)) + (1 - wx) * s[j] + wx * s[j + 1];
      v[ix] = m.at(ix) ? T(0) : p;
    }
  };
  for_each_block_with_scratch<T>(precision_name<T>("prolongation", "prolongation (float)"), comps, f.nz(), f.ny(),
                                 cnx + 1, double(comps) * double(Nf) * in_precision<T>(kProlongateCost), fine_row);
}

template void prolongate<double>(const Transfer&, int, const double*, double*, const double*, unsigned);
template void prolongate<float>(const Transfer&, int, const float*, float*, const float*, unsigned);

void prolongate_ref(const Transfer& t, int comps, const real* coarse, real* fine, const real* base) {
  const GridDims &f = t.fine, &c = t.coarse;
  for (int a = 0; a < comps; ++a)
    for (index iz = 0; iz < f.nz(); ++iz)
      for (index iy = 0; iy < f.ny(); ++iy)
        for (index ix = 0; ix < f.nx(); ++ix) {
          real s = 0;
          for (int k = 0; k < 8; ++k) {
            const int bx = k & 1, by = (k >> 1) & 1, bz = (k >> 2) & 1;
            const real w = (bx ? t.axis[0].w[ix] : 1 - t.axis[0].w[ix]) *
                           (by ? t.axis[1].w[iy] : 1 - t.axis[1].w[iy]) *
                           (bz ? t.axis[2].w[iz] : 1 - t.axis[2].w[iz]);
            s += w * coarse[a * c.nodes() +
                            c.node(t.axis[0].j0[ix] + bx, t.axis[1].j0[iy] + by, t.axis[2].j0[iz] + bz)];
          }
          const index at = a * f.nodes() + f.node(ix, iy, iz);
          fine[at] = base ? base[at] + s : s;
        }
}

template <class T>
void restrict_to_coarse(const Transfer& t, int comps, const T* fine, T* coarse, unsigned zero_faces) {
  TRESCA_ASSERT(comps >= 1 && comps <= 3 && index(t.axis[0].tstart.size()) == t.coarse.nx() + 1);
  // Per coarse row (jy, jz): sum the weighted fine rows of its y/z support
  // (4 to 16 of them) into one row buffer, four rows a pass (contiguous,
  // vectorised; a pass a row took 1.5 times as long), then gather along x:
  // along a halving axis coarse node j takes fine pair j's share of its
  // first coarse node and pair j-1's of its second (a lane per coarse node,
  // contiguous reads; the buffer has two zero entries each side), along
  // the general axis the transposed lists (scalar code on the CPU).
  const GridDims &f = t.fine, &c = t.coarse;
  const index Nf = f.nodes(), Nc = c.nodes(), fnx = f.nx();
  const index fny = f.ny(), cnx = c.nx(), cny = c.ny();
  const AxisView X(t.axis[0]), Y(t.axis[1]), Z(t.axis[2]);
  // component a's coarse row (jy, jz); acc: a fine row of the worker's own,
  // 2 entries more each side
  const auto coarse_row = [=](index a, index jz, index jy, T* buffer) {
    T* acc = buffer + 2;
    acc[-2] = acc[-1] = acc[fnx] = acc[fnx + 1] = 0;
    // the fine rows of its y/z support: (y0 + q % ny, z0 + q / ny), q < rows
    const index y0 = Y.tstart[jy], ny = Y.tstart[jy + 1] - y0, z0 = Z.tstart[jz];
    const index rows = ny * (Z.tstart[jz + 1] - z0);
    // four to a pass (the last pass's missing rows: its first again, weight
    // 0), the first pass writing acc
    if (rows == 0) {
#pragma omp simd
      for (index i = 0; i < fnx; ++i) acc[i] = 0;
    }
    for (index q0 = 0; q0 < rows; q0 += 4) {
      const T* r[4];
      T w[4];
      for (index u = 0; u < 4; ++u) {
        const index q = q0 + u < rows ? q0 + u : q0, ky = y0 + q % ny, kz = z0 + q / ny;
        r[u] = fine + a * Nf + fnx * (Y.tf[ky] + fny * Z.tf[kz]);
        w[u] = q0 + u < rows ? T(Z.tw[kz] * Y.tw[ky]) : T(0);
      }
      const T *r0 = r[0], *r1 = r[1], *r2 = r[2], *r3 = r[3];
      const T w0 = w[0], w1 = w[1], w2 = w[2], w3 = w[3];
      if (q0 == 0) {
#pragma omp simd  // vector loop (tests/check_vectorised.py)
        for (index i = 0; i < fnx; ++i) acc[i] = w0 * r0[i] + w1 * r1[i] + w2 * r2[i] + w3 * r3[i];
      } else {
#pragma omp simd  // vector loop (tests/check_vectorised.py)
        for (index i = 0; i < fnx; ++i) acc[i] += w0 * r0[i] + w1 * r1[i] + w2 * r2[i] + w3 * r3[i];
      }
    }
    const ConstrainedRow m(c, zero_faces, jy, jz);
    T* out = coarse + a * Nc + cnx * (jy + cny * jz);
    if (X.halving) {
#pragma omp simd  // vector loop (tests/check_vectorised.py)
      for (index j = 0; j < cnx; ++j) {
        const index i = 2 * j;
        const T w0 = T(X.pw[i]), w1 = T(X.pw[i + 1]), h0 = T(X.pw[i - 2]), h1 = T(X.pw[i - 1]);
        const T sx = (1 - w0) * acc[i] + (1 - w1) * acc[i + 1] + h0 * acc[i - 2] + h1 * acc[i - 1];
        out[j] = m.at(j) ? T(0) : sx;
      }
      return;
    }
    TRESCA_DEVICE_LANES
    for (index jx = 0; jx < cnx; ++jx) {
      T sx = 0;
      for (index kx = X.tstart[jx]; kx < X.tstart[jx + 1]; ++kx) sx += T(X.tw[kx]) * acc[X.tf[kx]];
      out[jx] = m.at(jx) ? T(0) : sx;
    }
  };
  for_each_block_with_scratch<T>(precision_name<T>("restriction", "restriction (float)"), comps, c.nz(), c.ny(),
                                 fnx + 4, double(comps) * double(Nf) * in_precision<T>(kRestrictCost), coarse_row);
}

template void restrict_to_coarse<double>(const Transfer&, int, const double*, double*, unsigned);
template void restrict_to_coarse<float>(const Transfer&, int, const float*, float*, unsigned);

void restrict_to_coarse_ref(const Transfer& t, int comps, const real* fine, real* coarse) {
  const GridDims &f = t.fine, &c = t.coarse;
  for (index i = 0; i < comps * c.nodes(); ++i) coarse[i] = 0;
  for (int a = 0; a < comps; ++a)
    for (index iz = 0; iz < f.nz(); ++iz)
      for (index iy = 0; iy < f.ny(); ++iy)
        for (index ix = 0; ix < f.nx(); ++ix)
          for (int k = 0; k < 8; ++k) {
            const int bx = k & 1, by = (k >> 1) & 1, bz = (k >> 2) & 1;
            const real w = (bx ? t.axis[0].w[ix] : 1 - t.axis[0].w[ix]) *
                           (by ? t.axis[1].w[iy] : 1 - t.axis[1].w[iy]) *
                           (bz ? t.axis[2].w[iz] : 1 - t.axis[2].w[iz]);
            coarse[a * c.nodes() +
                   c.node(t.axis[0].j0[ix] + bx, t.axis[1].j0[iy] + by, t.axis[2].j0[iz] + bz)] +=
                w * fine[a * f.nodes() + f.node(ix, iy, iz)];
          }
}

}  // namespace tresca
