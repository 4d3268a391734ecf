// The matrix-free elasticity apply against an assembled sparse K, its _ref
// twin, symmetry, the rigid-body kernel and the patch test.
#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/SparseCore>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "core/fem/assembly.hpp"
#include "core/fem/elasticity_operator.hpp"
#include "kernels/boundary_block.hpp"
#include "kernels/vector_ops.hpp"
#include "test_helpers.hpp"

namespace tresca {
using test::max_abs;
using test::max_abs_diff;
using test::random_vector;

namespace {
const unsigned kFaceSets[] = {0u, kFaceX0, kFaceX0 | kFaceZ0, 63u, kFaceY1 | kFaceZ1};
const index kSizes[][3] = {{3, 2, 5}, {7, 3, 2}, {1, 1, 1}, {2, 1, 3}, {17, 3, 5}};

std::vector<real> matvec(const ElasticityOperator& A, const std::vector<real>& x) {
  std::vector<real> y(x.size());
  A.apply(x.data(), y.data());
  return y;
}
}  // namespace

TEST(ElasticityApply, MatchesAssembledMatrixOnOddSizes) {
  for (auto& s : kSizes)
    for (unsigned faces : kFaceSets) {
      ElasticityOperator A(test::prism(s[0], s[1], s[2]), faces, 2.1e9, 0.277);
      const SparseMatrix K = assemble(A);
      auto x = random_vector(A.size(), 3);
      auto y = matvec(A, x);
      Eigen::Map<const Eigen::VectorXd> xv(x.data(), A.size());
      Eigen::VectorXd yref = K * xv;
      std::vector<real> yr(yref.data(), yref.data() + A.size());
      EXPECT_LT(max_abs_diff(y, yr), 1e-12 * max_abs(yr)) << s[0] << "x" << s[1] << "x" << s[2] << " faces " << faces;
    }
}

TEST(ElasticityApply, OptimisedEqualsReferenceIncludingPlaneRanges) {
  test::for_each_isa([&](const IsaKernels&) {
    for (auto& s : kSizes)
      for (unsigned faces : kFaceSets) {
        const GridDims g = test::prism(s[0], s[1], s[2]);
        const ElasticityStencil k = build_elasticity_stencil(g, faces, 1.0, 0.3);
        auto x = random_vector(k.size(), 5);
        for (index zb = 0; zb < g.nz(); ++zb) {
          const index ze = std::min(g.nz(), zb + 2);
          std::vector<real> y(k.size(), 7.0), yr(k.size(), 7.0);
          elasticity_apply(k, x.data(), y.data(), zb, ze);
          elasticity_apply_ref(k, x.data(), yr.data(), zb, ze);
          EXPECT_LT(max_abs_diff(y, yr), 1e-13 * max_abs(yr));
          // fused residual r = b - K x
          auto b = random_vector(k.size(), 6);
          std::vector<real> r(k.size(), 7.0), rr(k.size(), 7.0);
          elasticity_apply(k, x.data(), r.data(), zb, ze, b.data());
          elasticity_apply_ref(k, x.data(), rr.data(), zb, ze, b.data());
          EXPECT_LT(max_abs_diff(r, rr), 1e-13 * max_abs(yr));
          for (index iz = zb; iz < ze; ++iz)
            for (index n = iz * g.nx() * g.ny(); n < (iz + 1) * g.nx() * g.ny(); ++n)
              for (int a = 0; a < 3; ++a) {
                const index j = a * g.nodes() + n;
                EXPECT_NEAR(r[j], b[j] - yr[j], 1e-13 * max_abs(yr));
              }
        }
        std::vector<real> d(k.size()), dr(k.size());
        elasticity_diagonal(k, d.data());
        elasticity_diagonal_ref(k, dr.data());
        EXPECT_LT(max_abs_diff(d, dr), 1e-14 * max_abs(dr));
      }
  });
}

// the row-parallel form (the device's, here on host threads): the banded
// apply's answers to rounding (the same per-node sums in the same order;
// the compiler fuses multiply-adds differently in the two loops), on every
// size, face set and block of rows, plain and fused, in double and float;
// and on rows of 131 and 151 nodes, whose runs of 128 nodes and more a lane
// sweeps 4 nodes at a time in float (kernels/elasticity.cpp)
TEST(ElasticityApply, RowFormEqualsTheBandedApply) {
  std::vector<std::array<index, 3>> sizes = {{130, 1, 2}, {150, 2, 1}};
  for (auto& s : kSizes) sizes.push_back({s[0], s[1], s[2]});
  test::for_each_isa([&](const IsaKernels&) {
    for (auto& s : sizes)
      for (unsigned faces : kFaceSets) {
        const GridDims g = test::prism(s[0], s[1], s[2]);
        const ElasticityStencil k = build_elasticity_stencil(g, faces, 1.0, 0.3);
        const auto x = random_vector(k.size(), 5), b = random_vector(k.size(), 6);
        const RowBlock blocks[] = {{0, g.nz(), 0, g.ny()}, {g.nz() / 2, g.nz(), g.ny() / 2, g.ny()}};
        for (const RowBlock& rows : blocks)
          for (const real* bb : {(const real*)nullptr, b.data()}) {
            std::vector<real> y(k.size(), 7.0), yr(k.size(), 7.0);
            elasticity_apply(k, x.data(), y.data(), rows, bb);
            elasticity_apply_rows(view(k), x.data(), bb ? residual_out(bb, yr.data()) : operator_out(yr.data()), rows);
            EXPECT_LE(max_abs_diff(y, yr), 1e-14 * max_abs(y)) << s[0] << "x" << s[1] << "x" << s[2] << " faces " << faces;
          }
        // (float: the device's 4 nodes a lane, double's 1)
        const auto kf = stencil_in_precision<float>(k);
        const std::vector<float> xf(x.begin(), x.end()), bf(b.begin(), b.end());
        for (const RowBlock& rows : blocks)
          for (const float* bb : {(const float*)nullptr, bf.data()}) {
            std::vector<float> yf(k.size(), 7.0f), yfr(k.size(), 7.0f);
            elasticity_apply(kf, xf.data(), yf.data(), rows, bb);
            elasticity_apply_rows(view(kf), xf.data(), bb ? residual_out(bb, yfr.data()) : operator_out(yfr.data()),
                                  rows);
            float m = 0, d = 0;
            for (size_t i = 0; i < yf.size(); ++i) {
              m = std::max(m, std::abs(yf[i]));
              d = std::max(d, std::abs(yf[i] - yfr[i]));
            }
            EXPECT_LE(d, 1e-5f * m) << "float, " << s[0] << "x" << s[1] << "x" << s[2] << " faces " << faces;
          }
      }
  });
}

// The banded apply's sweep of one worker's rows (for_each_row_band): every
// row of the share once, in blocks of at most one band of rows or of one
// plane, for shares that start and end inside planes, span one, or many.
TEST(ElasticityApply, RowBandsCoverAWorkersRowsOnce) {
  const RowBlock blocks[] = {{0, 9, 0, 37}, {2, 7, 5, 18}, {0, 1, 0, 3}};
  for (const RowBlock& rows : blocks) {
    const index ny = rows.y_end - rows.y_begin, R = ny * (rows.z_end - rows.z_begin);
    for (index w : {1, 2, 3, 5, 16, 64})
      for (index t = 0; t < w; ++t) {
        const Share s = host_share(R, t, w);
        std::vector<int> seen(std::size_t(R), 0);
        for_each_row_band(rows, s, 16, [&](const RowBlock& b) {
          EXPECT_TRUE(b.z_end - b.z_begin == 1 || b.y_end - b.y_begin <= 16);
          for (index z = b.z_begin; z < b.z_end; ++z)
            for (index y = b.y_begin; y < b.y_end; ++y) {
              ASSERT_TRUE(rows.z_begin <= z && z < rows.z_end && rows.y_begin <= y && y < rows.y_end);
              ++seen[std::size_t((z - rows.z_begin) * ny + (y - rows.y_begin))];
            }
        });
        for (index r = 0; r < R; ++r)
          EXPECT_EQ(seen[std::size_t(r)], s.begin <= r && r < s.end ? 1 : 0) << "row " << r << ", worker " << t << " of " << w;
      }
  }
}

// The apply on any number of threads, each with its share of the rows
// (shares that cut planes anywhere): the same answer bit for bit, each
// entry being the same sum whoever computes it.
TEST(ElasticityApply, EveryThreadCountGivesTheSameAnswerBitForBit) {
  const GridDims g = test::prism(23, 12, 10);
  const ElasticityStencil k = build_elasticity_stencil(g, kFaceX0 | kFaceZ0, 1.0, 0.3);
  ASSERT_TRUE(worth_threads(double(g.nodes()) * apply_cost(operator_out<real>(nullptr))));
  const auto x = random_vector(k.size(), 41), b = random_vector(k.size(), 42);
  const int threads = omp_get_max_threads();
  std::vector<real> y1(k.size()), r1(k.size());
  omp_set_num_threads(1);
  elasticity_apply(k, x.data(), y1.data(), RowBlock{0, g.nz(), 0, g.ny()});
  elasticity_apply(k, x.data(), r1.data(), RowBlock{0, g.nz(), 0, g.ny()}, b.data());
  for (int w : {2, 3, 5, 8}) {
    omp_set_num_threads(w);
    std::vector<real> y(k.size(), 7.0), r(k.size(), 7.0);
    elasticity_apply(k, x.data(), y.data(), RowBlock{0, g.nz(), 0, g.ny()});
    elasticity_apply(k, x.data(), r.data(), RowBlock{0, g.nz(), 0, g.ny()}, b.data());
    EXPECT_EQ(y, y1) << w << " threads";
    EXPECT_EQ(r, r1) << w << " threads";
  }
  omp_set_num_threads(threads);
}

// The smoother's Chebyshev step fused into the apply (kernels/apply_out.hpp)
// against the _ref twin's residual and the update written out: banded and
// row forms, every instruction set, every face set, blocks of rows, the
// first step (s = 0: y full of NaN, not read) and a later one; sizes whose
// runs end in a partial vector (the banded apply's overlapping last vector
// must put each entry once: the step is not idempotent).
TEST(ElasticityApply, ChebyshevStepIsTheResidualAndTheUpdateInOneSweep) {
  const index sizes[][3] = {{3, 2, 5}, {17, 3, 5}, {29, 2, 3}, {61, 1, 2}, {150, 1, 2}};
  const real t = 0.37;
  test::for_each_isa([&](const IsaKernels&) {
    for (auto& sz : sizes)
      for (unsigned faces : kFaceSets) {
        const GridDims g = test::prism(sz[0], sz[1], sz[2]);
        const ElasticityStencil k = build_elasticity_stencil(g, faces, 1.0, 0.3);
        const index n = k.size(), N = g.nodes();
        const auto x = random_vector(n, 31), b = random_vector(n, 32), p0 = random_vector(n, 33);
        std::vector<real> diag(n);
        elasticity_diagonal_ref(k, diag.data());
        const std::vector<real> dinv = test::step_weights(g, faces, diag, 34);
        std::vector<real> r(n);
        elasticity_apply_ref(k, x.data(), r.data(), 0, g.nz(), b.data());
        const RowBlock blocks[] = {{0, g.nz(), 0, g.ny()}, {g.nz() / 2, g.nz(), g.ny() / 2, g.ny()}};
        for (const RowBlock& rows : blocks)
          for (real s : {0.0, 0.8})
            for (bool from_zero : {false, true})
              for (bool row_form : {false, true}) {
                // y holds the iterate before x (not read where s == 0 or
                // that iterate is zero: NaN there)
                const bool unread = s == 0 || from_zero;
                std::vector<real> y = p0;
                if (unread) std::fill(y.begin(), y.end(), std::numeric_limits<real>::quiet_NaN());
                const std::vector<real> y0 = y;
                const ApplyOut<real> out = chebyshev_out<real>(b.data(), dinv.data(), s, t, y.data(), from_zero);
                if (row_form)
                  elasticity_apply_rows(view(k), x.data(), out, rows);
                else
                  elasticity_apply(k, x.data(), out, rows);
                real err_y = 0;
                bool untouched = true;
                for (index iz = 0; iz < g.nz(); ++iz)
                  for (index iy = 0; iy < g.ny(); ++iy)
                    for (index ix = 0; ix < g.nx(); ++ix)
                      for (int a = 0; a < 3; ++a) {
                        const index j = a * N + g.node(ix, iy, iz);
                        const bool in = rows.z_begin <= iz && iz < rows.z_end && rows.y_begin <= iy && iy < rows.y_end;
                        if (!in) {
                          untouched = untouched && (unread ? std::isnan(y[j]) : y[j] == y0[j]);
                          continue;
                        }
                        const real prev = from_zero ? 0 : p0[j];
                        const real want = x[j] + s * (x[j] - prev) + t * dinv[j] * r[j];
                        err_y = std::max(err_y, std::abs(y[j] - want));
                      }
                const std::string where = std::to_string(sz[0]) + "x" + std::to_string(sz[1]) + "x" +
                                          std::to_string(sz[2]) + " faces " + std::to_string(faces) +
                                          (row_form ? " rows" : " banded") + " s " + std::to_string(s) +
                                          (from_zero ? " from zero" : "");
                const real scale = max_abs(r) * 4 + max_abs(x);
                EXPECT_LT(err_y, 1e-13 * scale) << where;
                EXPECT_TRUE(untouched) << where;
              }
        // single precision: the same step to float rounding
        const auto kf = stencil_in_precision<float>(k);
        std::vector<float> xf(x.begin(), x.end()), bf(b.begin(), b.end()), yf(p0.begin(), p0.end()),
            dif(dinv.begin(), dinv.end());
        elasticity_apply(kf, xf.data(), chebyshev_out<float>(bf.data(), dif.data(), 0.8f, float(t), yf.data()),
                         RowBlock{0, g.nz(), 0, g.ny()});
        real err = 0;
        for (index j = 0; j < n; ++j)
          err = std::max(err, std::abs(real(yf[j]) - (x[j] + 0.8 * (x[j] - p0[j]) + t * dinv[j] * r[j])));
        EXPECT_LT(err, 2e-5 * (max_abs(r) * 4 + max_abs(x))) << "float, faces " << faces;
      }
  });
}

TEST(ElasticityApply, SinglePrecisionMatchesReferenceToFloatRounding) {
  test::for_each_isa([&](const IsaKernels&) {
    for (auto& s : kSizes)
      for (unsigned faces : kFaceSets) {
        const GridDims g = test::prism(s[0], s[1], s[2]);
        const ElasticityStencil k = build_elasticity_stencil(g, faces, 2.1e9, 0.277);
        const ElasticityStencilT<float> kf = stencil_in_precision<float>(k);
        const auto x = random_vector(k.size(), 5), b = random_vector(k.size(), 6);
        std::vector<float> xf(x.begin(), x.end()), bf(b.begin(), b.end()), yf(k.size()), rf(k.size());
        // the reference on the float-rounded input, so only the kernel's rounding differs
        const std::vector<real> xr(xf.begin(), xf.end()), br(bf.begin(), bf.end());
        std::vector<real> yr(k.size()), rr(k.size());
        elasticity_apply_ref(k, xr.data(), yr.data(), 0, g.nz());
        elasticity_apply_ref(k, xr.data(), rr.data(), 0, g.nz(), br.data());
        elasticity_apply<float>(kf, xf.data(), yf.data(), 0, g.nz());
        elasticity_apply<float>(kf, xf.data(), rf.data(), 0, g.nz(), bf.data());
        // 27-point sums of terms up to |Ke| |x|: float rounding ~ 1e-7 of the largest term
        const real scale = max_abs(std::vector<real>(k.Ke.begin(), k.Ke.end())) * 27 * 3;
        EXPECT_LT(max_abs_diff(std::vector<real>(yf.begin(), yf.end()), yr), 1e-6 * scale)
            << s[0] << "x" << s[1] << "x" << s[2] << " faces " << faces;
        EXPECT_LT(max_abs_diff(std::vector<real>(rf.begin(), rf.end()), rr), 1e-6 * scale);
      }
  });
}

TEST(ElasticityApply, IsSymmetric) {
  for (unsigned faces : kFaceSets) {
    ElasticityOperator A(test::prism(7, 3, 2), faces, 2.1e9, 0.277);
    auto x = random_vector(A.size(), 11), y = random_vector(A.size(), 12);
    auto Ax = matvec(A, x), Ay = matvec(A, y);
    const real xay = dot_ref(A.size(), x.data(), Ay.data()), yax = dot_ref(A.size(), y.data(), Ax.data());
    EXPECT_LT(std::abs(xay - yax), 1e-13 * std::abs(xay));
  }
}

TEST(ElasticityApply, RigidBodyModesLieInKernelWithoutDirichlet) {
  const GridDims g = test::prism(5, 3, 4);
  ElasticityOperator A(g, 0, 2.1e9, 0.277);
  const index N = g.nodes();
  const real kscale = A.diagonal()[0];
  for (int mode = 0; mode < 6; ++mode) {
    std::vector<real> u(3 * N, 0);
    for (index iz = 0; iz < g.nz(); ++iz)
      for (index iy = 0; iy < g.ny(); ++iy)
        for (index ix = 0; ix < g.nx(); ++ix) {
          const real x[3] = {ix * g.hx(), iy * g.hy(), iz * g.hz()};
          const index n = g.node(ix, iy, iz);
          if (mode < 3) {
            u[mode * N + n] = 1;
          } else {
            const int ax = mode - 3, p = (ax + 1) % 3, q = (ax + 2) % 3;
            u[p * N + n] = -x[q];
            u[q * N + n] = x[p];
          }
        }
    EXPECT_LT(max_abs(matvec(A, u)), 1e-12 * kscale) << "mode " << mode;
  }
}

TEST(ElasticityApply, PatchTestLinearFieldHasZeroInteriorResidual) {
  // u = G x + c is an exact solution of the homogeneous equations: K u vanishes
  // at every node that is not on the boundary of the box.
  const GridDims g = test::prism(6, 5, 4);
  ElasticityOperator A(g, 0, 2.1e9, 0.277);
  const index N = g.nodes();
  const real G[3][3] = {{0.1, -0.3, 0.2}, {0.05, 0.4, -0.1}, {-0.2, 0.15, 0.3}};
  std::vector<real> u(3 * N);
  for (index iz = 0; iz < g.nz(); ++iz)
    for (index iy = 0; iy < g.ny(); ++iy)
      for (index ix = 0; ix < g.nx(); ++ix) {
        const real x[3] = {ix * g.hx(), iy * g.hy(), iz * g.hz()};
        for (int a = 0; a < 3; ++a)
          u[a * N + g.node(ix, iy, iz)] = G[a][0] * x[0] + G[a][1] * x[1] + G[a][2] * x[2] + 0.01 * a;
      }
  auto y = matvec(A, u);
  real interior = 0, boundary = 0;
  for (index iz = 0; iz < g.nz(); ++iz)
    for (index iy = 0; iy < g.ny(); ++iy)
      for (index ix = 0; ix < g.nx(); ++ix) {
        const bool inside = ix > 0 && ix < g.ex && iy > 0 && iy < g.ey && iz > 0 && iz < g.ez;
        for (int a = 0; a < 3; ++a) {
          const real v = std::abs(y[a * N + g.node(ix, iy, iz)]);
          (inside ? interior : boundary) = std::max(inside ? interior : boundary, v);
        }
      }
  EXPECT_GT(boundary, 1e6);  // tractions of the linear field on the boundary are not zero
  EXPECT_LT(interior, 1e-12 * boundary);
}

TEST(ZeroConstrained, ZeroesExactlyTheConstrainedFaces) {
  for (auto& s : kSizes)
    for (unsigned faces : kFaceSets) {
      const GridDims g = test::prism(s[0], s[1], s[2]);
      auto v = random_vector(3 * g.nodes(), 9);
      const auto before = v;
      zero_constrained(g, faces, v.data());
      for (index iz = 0; iz < g.nz(); ++iz)
        for (index iy = 0; iy < g.ny(); ++iy)
          for (index ix = 0; ix < g.nx(); ++ix)
            for (int a = 0; a < 3; ++a) {
              const index i = a * g.nodes() + g.node(ix, iy, iz);
              EXPECT_EQ(v[i], node_constrained(g, faces, ix, iy, iz) ? 0.0 : before[i]);
            }
    }
}

TEST(BottomBlock, OptimisedEqualsReferenceAndAssembly) {
  const GridDims g = test::prism(4, 3, 2);
  ElasticityOperator A(g, kFaceX0, 1.0, 0.3);
  const index M = g.nx() * g.ny();
  const std::vector<real> B = random_vector(4 * M, 21);
  A.set_bottom_block(B);
  auto x = random_vector(A.size(), 22);
  std::vector<real> y(A.size(), 0), yr(A.size(), 0);
  bottom_block_apply(g, A.bottom_block().data(), x.data(), operator_out(y.data()));
  bottom_block_apply_ref(g, 1.0, A.bottom_block().data(), x.data(), yr.data());
  EXPECT_LT(max_abs_diff(y, yr), 1e-15);
  const SparseMatrix K = assemble(A);
  Eigen::Map<const Eigen::VectorXd> xv(x.data(), A.size());
  Eigen::VectorXd ye = K * xv;
  auto ya = matvec(A, x);
  EXPECT_LT(max_abs_diff(ya, std::vector<real>(ye.data(), ye.data() + A.size())), 1e-12 * ye.cwiseAbs().maxCoeff());
  // residual with the block: r = b - (K + B) x
  auto b = random_vector(A.size(), 23);
  std::vector<real> r(A.size());
  A.residual(b.data(), x.data(), r.data());
  real err = 0;
  for (index i = 0; i < A.size(); ++i) err = std::max(err, std::abs(r[i] - (b[i] - ye[i])));
  EXPECT_LT(err, 1e-12 * ye.cwiseAbs().maxCoeff());
  // the smoother's fused Chebyshev step with the block: y = x + s (x - y) + t dinv r
  const std::vector<real> dinv = test::step_weights(g, kFaceX0, A.diagonal().to_vector(), 24);
  const auto p0 = random_vector(A.size(), 25);
  std::vector<real> ys = p0;
  A.chebyshev_step(b.data(), x.data(), ys.data(), dinv.data(), 0.6, 0.4);
  real err_y = 0;
  for (index i = 0; i < A.size(); ++i)
    err_y = std::max(err_y, std::abs(ys[i] - (x[i] + 0.6 * (x[i] - p0[i]) + 0.4 * dinv[i] * (b[i] - ye[i]))));
  EXPECT_LT(err_y, 1e-12 * ye.cwiseAbs().maxCoeff());
}

}  // namespace tresca
