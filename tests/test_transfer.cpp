// Grid transfers: optimised equals reference, restriction is the exact
// transpose of prolongation, and prolongation reproduces trilinear fields.
#include <gtest/gtest.h>

#include "kernels/elasticity.hpp"
#include "kernels/transfer.hpp"
#include "kernels/vector_ops.hpp"
#include "test_helpers.hpp"

namespace tresca {
using test::max_abs_diff;
using test::random_vector;

namespace {
// fine and coarse prisms (elements per axis): the multigrid's halvings,
// nested and not (coarse e = ceil(fine e / 2)), and a mesh of another
// level's (12 -> 9: the general axis, as in the nested iteration)
const index kPairs[][6] = {
    {23, 12, 12, 12, 6, 6}, {7, 3, 5, 4, 2, 3}, {8, 4, 4, 4, 2, 2}, {5, 1, 2, 3, 1, 1}, {12, 6, 7, 9, 4, 5}};
}  // namespace

// The kernels take the pairwise path along x wherever the axis halves: on
// every multigrid transfer (coarse e = ceil(fine e / 2)) and on no other
TEST(Transfer, EveryHalvingAxisIsRunInPairs) {
  for (index e = 1; e <= 700; ++e) {
    const Transfer t = build_transfer(test::prism(e, 1, 1), test::prism((e + 1) / 2, 1, 1));
    EXPECT_TRUE(t.axis[0].halving()) << e;
    EXPECT_EQ(index(t.axis[0].pair_w.size()), 2 * ((e + 1) / 2 + 1) + 2);
  }
  EXPECT_FALSE(build_transfer(test::prism(12, 1, 1), test::prism(9, 1, 1)).axis[0].halving());
  EXPECT_FALSE(build_transfer(test::prism(8, 1, 1), test::prism(3, 1, 1)).axis[0].halving());
  EXPECT_FALSE(build_transfer(test::prism(8, 1, 1), test::prism(8, 1, 1)).axis[0].halving());
}

TEST(Transfer, OptimisedEqualsReferenceOnNonNestedGrids) {
  for (auto& p : kPairs) {
    const Transfer t = build_transfer(test::prism(p[0], p[1], p[2]), test::prism(p[3], p[4], p[5]));
    auto c = random_vector(2 * t.coarse.nodes(), 1);
    auto f = random_vector(2 * t.fine.nodes(), 2);
    std::vector<real> pf(f.size()), pfr(f.size()), rc(c.size()), rcr(c.size());
    prolongate(t, 2, c.data(), pf.data());
    prolongate_ref(t, 2, c.data(), pfr.data());
    restrict_to_coarse(t, 2, f.data(), rc.data());
    restrict_to_coarse_ref(t, 2, f.data(), rcr.data());
    EXPECT_LT(max_abs_diff(pf, pfr), 1e-14);
    // onto a base: fine += P coarse in place, and out = f + P coarse into
    // another vector, the same bits
    std::vector<real> acc(f), accr(f), out(f.size(), -7.0);
    prolongate(t, 2, c.data(), acc.data(), acc.data());
    prolongate_ref(t, 2, c.data(), accr.data(), accr.data());
    prolongate(t, 2, c.data(), out.data(), f.data());
    EXPECT_LT(max_abs_diff(acc, accr), 1e-14);
    EXPECT_EQ(out, acc);
    for (size_t i = 0; i < f.size(); ++i) EXPECT_NEAR(acc[i], f[i] + pfr[i], 1e-14);
    EXPECT_LT(max_abs_diff(rc, rcr), 1e-13);
    // <P c, f> = <c, P^T f>
    const real a = dot_ref(index(f.size()), pf.data(), f.data()), b = dot_ref(index(c.size()), c.data(), rc.data());
    EXPECT_LT(std::abs(a - b), 1e-12 * std::abs(a));
  }
}

// with zero_faces the transfers write 0 on the output's faces in the same
// sweep: equal to the transfer followed by zero_constrained, for every set
// of faces, on nested and non-nested grids, double and float; the other
// entries untouched
template <class T>
void check_zero_faces() {
  for (auto& p : kPairs) {
    const Transfer t = build_transfer(test::prism(p[0], p[1], p[2]), test::prism(p[3], p[4], p[5]));
    const auto cd = random_vector(3 * t.coarse.nodes(), 3), fd = random_vector(3 * t.fine.nodes(), 4);
    const std::vector<T> c(cd.begin(), cd.end()), f(fd.begin(), fd.end());
    for (unsigned faces = 0; faces < 64; faces += (faces < 8 ? 1 : 7)) {
      std::vector<T> pf(f), want_pf(f), out(f.size(), T(-7)), rc(c.size()), want_rc(c.size());
      prolongate<T>(t, 3, c.data(), pf.data(), pf.data(), faces);
      prolongate<T>(t, 3, c.data(), out.data(), f.data(), faces);  // (out of place)
      prolongate<T>(t, 3, c.data(), want_pf.data(), want_pf.data());
      zero_constrained<T>(t.fine, faces, want_pf.data());
      EXPECT_EQ(out, want_pf) << "prolongation out of place, faces " << faces;
      restrict_to_coarse<T>(t, 3, f.data(), rc.data(), faces);
      restrict_to_coarse<T>(t, 3, f.data(), want_rc.data());
      zero_constrained<T>(t.coarse, faces, want_rc.data());
      EXPECT_EQ(pf, want_pf) << "prolongation, faces " << faces << ", fine " << p[0] << "x" << p[1] << "x" << p[2];
      EXPECT_EQ(rc, want_rc) << "restriction, faces " << faces << ", coarse " << p[3] << "x" << p[4] << "x" << p[5];
    }
  }
}
TEST(Transfer, ZeroFacesIsTheTransferThenZeroConstrained) {
  check_zero_faces<double>();
  check_zero_faces<float>();
}

TEST(Transfer, ProlongationReproducesTrilinearFields) {
  for (auto& p : kPairs) {
    const GridDims F = test::prism(p[0], p[1], p[2]), C = test::prism(p[3], p[4], p[5]);
    const Transfer t = build_transfer(F, C);
    auto field = [](real x, real y, real z) { return 1 + 2 * x - y + 0.5 * z + 0.3 * x * y - 0.7 * y * z + x * y * z; };
    std::vector<real> c(C.nodes()), f(F.nodes());
    for (index iz = 0; iz < C.nz(); ++iz)
      for (index iy = 0; iy < C.ny(); ++iy)
        for (index ix = 0; ix < C.nx(); ++ix) c[C.node(ix, iy, iz)] = field(ix * C.hx(), iy * C.hy(), iz * C.hz());
    prolongate(t, 1, c.data(), f.data());
    // exact only for fields linear per coarse cell: use the linear part
    auto lin = [](real x, real y, real z) { return 1 + 2 * x - y + 0.5 * z; };
    for (index iz = 0; iz < C.nz(); ++iz)
      for (index iy = 0; iy < C.ny(); ++iy)
        for (index ix = 0; ix < C.nx(); ++ix) c[C.node(ix, iy, iz)] = lin(ix * C.hx(), iy * C.hy(), iz * C.hz());
    prolongate(t, 1, c.data(), f.data());
    real err = 0;
    for (index iz = 0; iz < F.nz(); ++iz)
      for (index iy = 0; iy < F.ny(); ++iy)
        for (index ix = 0; ix < F.nx(); ++ix)
          err = std::max(err, std::abs(f[F.node(ix, iy, iz)] - lin(ix * F.hx(), iy * F.hy(), iz * F.hz())));
    EXPECT_LT(err, 1e-13);
    (void)field;
  }
}

}  // namespace tresca
