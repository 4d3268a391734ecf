// The operator and the V-cycle on a rank's slab (core/fem, core/multigrid,
// core/parallel) held against the same on the whole grid, on every rank. Run by CTest under mpirun with 2 and 3
// ranks (mpi.*), and as one rank. Every rank builds the whole grid's
// vectors too and compares its own slab with them.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/fem/elasticity_operator.hpp"
#include "core/parallel/comm.hpp"
#include "core/parallel/comm_model.hpp"
#include "core/parallel/row_fetch.hpp"
#include "core/multigrid/multigrid.hpp"
#include "kernels/boundary_block.hpp"
#include "core/solvers/cg.hpp"
#include "kernels/vector_ops.hpp"
#include "test_helpers.hpp"

namespace tresca {
namespace {

const Comm& world() { return Comm::world(); }

// K of the inner problem: clamped on x = 0 and the contact face z = 0
constexpr unsigned kFaces = kFaceX0 | kFaceZ0;

// the owned rows of a local vector against the same rows of a global one
real max_owned_diff(const Slab& s, const std::vector<real>& local, const std::vector<real>& global) {
  std::vector<real> mine(global);
  local_to_global(s, local.data(), mine.data());
  return test::max_abs_diff(mine, global);
}

}  // namespace

TEST(Slab, RowsPartitionTheGridAndKeepTheSpacing) {
  for (index ey : {1, 5, 16, 33})
    for (int ranks = 1; ranks <= std::min<index>(7, ey + 1); ++ranks) {
      const GridDims g = test::prism(6, ey, 3);
      index next = 0;
      for (int r = 0; r < ranks; ++r) {
        const Slab s = make_slab(g, r, ranks);
        EXPECT_EQ(s.y_begin, next);
        EXPECT_GE(s.owned_rows(), 1);
        next = s.y_end;
        EXPECT_NEAR(s.local.hy(), g.hy(), 1e-15 * g.hy()) << "ey " << ey << " rank " << r << "/" << ranks;
        EXPECT_EQ(s.local.ny(), s.owned_rows() + s.lo + s.hi);
        EXPECT_NEAR(s.local.y0, g.y0 + g.hy() * real(s.y_begin - s.lo), 1e-14);
        EXPECT_EQ(s.local.nx(), g.nx());
        EXPECT_EQ(s.local.nz(), g.nz());
      }
      EXPECT_EQ(next, g.ny());
    }
  EXPECT_THROW(make_slab(test::prism(4, 2, 2), 0, 4), std::invalid_argument);
}

TEST(SlabElasticity, OwnedRowsOfTheApplyEqualTheWholeGridsBitForBit) {
  for (const GridDims& g : {test::prism(8, 8, 4), test::prism(7, 5, 3), test::prism(16, 12, 6)}) {
    if (g.ny() < world().size()) continue;
    const Slab s = make_slab(g, world().rank(), world().size());
    const std::vector<real> xg = test::random_vector(3 * g.nodes(), 3);
    std::vector<real> yg(xg.size());
    ElasticityOperator(g, kFaces, 2.1e9, 0.277).apply(xg.data(), yg.data());
    const ElasticityOperator K(s, kFaces, 2.1e9, 0.277);
    std::vector<real> x(K.size()), y(K.size(), 1.0);
    global_to_local(s, xg.data(), x.data());
    K.zero_ghosts(x.data());  // the ghosts must come from the exchange
    if (world().size() > 1) {  // apply reads the ghost rows as they are: stale ones give another answer
      K.apply(x.data(), y.data());
      EXPECT_GT(world().max(max_owned_diff(s, y, yg)), 0.0);
    }
    K.update_ghosts(x.data());
    K.apply(x.data(), y.data());
    EXPECT_EQ(max_owned_diff(s, y, yg), 0.0) << g.ex << "x" << g.ey << "x" << g.ez;
    // the ghost rows of y are zero, so local dots count each entry once
    std::vector<real> yy(y);
    K.zero_ghosts(yy.data());
    EXPECT_EQ(test::max_abs_diff(yy, y), 0.0);
    const real local = dot(K.size(), y.data(), y.data());
    EXPECT_NEAR(world().sum(local), dot(index(yg.size()), yg.data(), yg.data()), 1e-12 * dot(index(yg.size()), yg.data(), yg.data()));
  }
}

// the contact planes (z = 0 and 1, what S needs of K): the owned rows of
// the distributed apply_planes equal the whole grid's, and the planes
// outside the range are left untouched (issue 19)
TEST(SlabElasticity, ApplyPlanesEqualsTheWholeGridsOnItsPlanesOnly) {
  for (const GridDims& g : {test::prism(8, 8, 4), test::prism(7, 5, 3)}) {
    if (g.ny() < world().size()) continue;
    const Slab s = make_slab(g, world().rank(), world().size());
    const std::vector<real> xg = test::random_vector(3 * g.nodes(), 5);
    std::vector<real> yg(xg.size(), 7.0);
    ElasticityOperator(g, kFaces, 2.1e9, 0.277).apply_planes(xg.data(), yg.data(), 0, 2);
    const ElasticityOperator K(s, kFaces, 2.1e9, 0.277);
    std::vector<real> x(K.size()), y(K.size(), 7.0);
    global_to_local(s, xg.data(), x.data());
    K.zero_ghosts(x.data());  // the ghosts must come from the exchange
    K.update_ghosts(x.data());
    K.apply_planes(x.data(), y.data(), 0, 2);
    EXPECT_EQ(max_owned_diff(s, y, yg), 0.0) << g.ex << "x" << g.ey << "x" << g.ez;
    const GridDims& l = s.local;
    for (int c = 0; c < 3; ++c)
      for (index iz = 2; iz < l.nz(); ++iz)
        for (index iy = s.lo; iy < s.lo + s.owned_rows(); ++iy)
          for (index ix = 0; ix < l.nx(); ++ix) ASSERT_EQ(y[c * l.nodes() + l.node(ix, iy, iz)], 7.0) << "plane " << iz;
  }
}

TEST(SlabElasticity, ExchangeFillsTheGhostRowsAndCountsAsTheModelSays) {
  const GridDims g = test::prism(9, 10, 4);
  if (g.ny() < world().size()) GTEST_SKIP();
  const Slab s = make_slab(g, world().rank(), world().size());
  const std::vector<real> xg = test::random_vector(3 * g.nodes(), 5);
  const ElasticityOperator K(s, kFaces, 1, 0.3);
  std::vector<real> x(K.size()), expected(K.size());
  global_to_local(s, xg.data(), expected.data());
  x = expected;
  K.zero_ghosts(x.data());
  K.update_ghosts(x.data());
  EXPECT_EQ(test::max_abs_diff(x, expected), 0.0);
  const CommVolume model = slab_apply_halo(g, int(s.lo + s.hi));
  EXPECT_EQ(double(K.halo_counts().messages), model.messages);
  EXPECT_EQ(K.halo_counts().bytes, model.bytes);
  EXPECT_EQ(K.halo_counts().exchanges, world().size() > 1 ? 1 : 0);
  // an interior slab is a box decomposition 1 x P
  if (s.lo && s.hi) {
    EXPECT_EQ(apply_halo(g, 1, world().size()).bytes, model.bytes);
  }
}

TEST(SlabCG, SameIterationsAndSolutionAsTheWholeGrid) {
  const GridDims g = test::prism(12, 10, 5);
  if (g.ny() < world().size()) GTEST_SKIP();
  const Slab s = make_slab(g, world().rank(), world().size());
  // the whole grid: K, Jacobi, CG on one rank
  const ElasticityOperator Kg(g, kFaces, 2.1e9, 0.277);
  std::vector<real> bg = test::random_vector(3 * g.nodes(), 11);
  zero_constrained(g, kFaces, bg.data());
  const Field<real> dg = Kg.diagonal();
  struct Jacobi : LinearOperator {
    const Field<real>& d;
    explicit Jacobi(const Field<real>& d_) : d(d_) {}
    index size() const override { return index(d.size()); }
    void apply(const real* r, real* z) const override {
      for (size_t i = 0; i < d.size(); ++i) z[i] = r[i] / d[i];
    }
  } Mg(dg);
  CGOptions o;
  o.rtol = 1e-10;
  o.max_iterations = 5000;
  CGWorkspace ws;
  std::vector<real> ug(bg.size());
  const SolveStats sg = pcg(Kg, &Mg, bg.data(), ug.data(), o, ws);
  ASSERT_TRUE(sg.ok());
  // the slabs
  const ElasticityOperator K(s, kFaces, 2.1e9, 0.277);
  const JacobiPreconditioner M(K);
  std::vector<real> b(K.size()), u(K.size());
  global_to_local(s, bg.data(), b.data());
  K.zero_ghosts(b.data());
  o.reduction = &world();
  const SolveStats sd = pcg(K, &M, b.data(), u.data(), o, ws);
  ASSERT_TRUE(sd.ok());
  EXPECT_NEAR(sd.iterations, sg.iterations, 1);  // the ranks' partial sums round differently
  EXPECT_LE(max_owned_diff(s, u, ug), 1e-9 * test::max_abs(ug));
  if (world().size() == 1) {
    EXPECT_EQ(sd.iterations, sg.iterations);
  }
}

TEST(RowFetch, AnyRangeOfRowsFromTheirOwners) {
  const GridDims g = test::prism(5, 11, 3);
  if (g.ny() < world().size()) GTEST_SKIP();
  const Slab s = make_slab(g, world().rank(), world().size());
  const std::vector<real> xg = test::random_vector(3 * g.nodes(), 8);
  std::vector<real> x(3 * s.local.nodes());
  global_to_local(s, xg.data(), x.data());
  // a different range on every rank, crossing the owners' boundaries
  const index a = world().rank() % 4, b = g.ny() - (world().rank() % 3);
  RowFetch f(s, a, b);
  std::vector<real> out(3 * f.box().nodes());
  f.fetch(x.data(), out.data());
  const GridDims& box = f.box();
  real diff = 0;
  for (int c = 0; c < 3; ++c)
    for (index iz = 0; iz < g.nz(); ++iz)
      for (index iy = a; iy < b; ++iy)
        for (index ix = 0; ix < g.nx(); ++ix)
          diff = std::max(diff, std::abs(out[c * box.nodes() + box.node(ix, iy - a, iz)] - xg[c * g.nodes() + g.node(ix, iy, iz)]));
  EXPECT_EQ(diff, 0.0);
}

// MG-CG on K_ii (u = 0 on x = 0 and the contact face) with the V-cycle on
// the ranks' slabs against the same on the whole grid: the same iterations
// (+-1: the ranks' partial sums round differently) and solution, bit for bit
// on one rank; fine levels split (64 nodes per rank suffice here, so two
// levels are split and the third whole)
TEST(SlabMultigrid, CGMatchesTheWholeGridMultigrid) {
  for (const GridDims& g : {test::prism(32, 24, 16), test::prism(27, 19, 11)})
  for (Precision prec : {Precision::double_precision, Precision::single_precision}) {
    MGOptions mo;
    mo.precision = prec;
    const Multigrid mg(g, kFaces, 2.1e9, 0.277, mo);
    const Multigrid dmg(GridHierarchy::build(g, mo.coarse_nodes, world(), 64), elasticity_on(kFaces, 2.1e9, 0.277), mo);
    ASSERT_EQ(dmg.num_levels(), mg.num_levels());
    if (world().size() > 1) {
      EXPECT_GE(dmg.hierarchy()->distributed_levels(), 2) << dmg.describe();
    }
    for (int l = 0; l + 1 < mg.num_levels(); ++l) EXPECT_NEAR(dmg.lmax(l), 0, 1e9);  // finite
    std::vector<real> bg = test::random_vector(3 * g.nodes(), 21);
    zero_constrained(g, kFaces, bg.data());
    CGOptions o;
    o.rtol = 1e-10;
    CGWorkspace ws;
    std::vector<real> ug(bg.size());
    const SolveStats sg = pcg(mg.op(0), &mg, bg.data(), ug.data(), o, ws);
    ASSERT_TRUE(sg.ok());
    const Slab& s = dmg.op(0).slab();
    std::vector<real> b(dmg.size()), u(dmg.size());
    global_to_local(s, bg.data(), b.data());
    dmg.op(0).zero_ghosts(b.data());
    o.reduction = dmg.reduction();
    const SolveStats sd = pcg(dmg.op(0), &dmg, b.data(), u.data(), o, ws);
    ASSERT_TRUE(sd.ok()) << dmg.describe();
    EXPECT_NEAR(sd.iterations, sg.iterations, 1) << dmg.describe();
    EXPECT_LE(max_owned_diff(s, u, ug), 1e-8 * test::max_abs(ug)) << dmg.describe();
    if (world().size() == 1) {
      EXPECT_EQ(sd.iterations, sg.iterations);
      EXPECT_EQ(test::max_abs_diff(u, ug), 0.0);
    }
  }
}

// The Newton-step preconditioner's operator K + B (K clamped on x = 0 only,
// B a random SPD 2x2 + 1 block per bottom node): MG-CG with the V-cycle on
// the slabs (B projected to every level, each rank its rows) against the
// whole grid's
TEST(SlabMultigrid, BottomBlockCGMatchesTheWholeGridMultigrid) {
  const GridDims g = test::prism(24, 20, 8);
  const index M = g.nx() * g.ny();
  std::vector<real> B(4 * M);
  const std::vector<real> rnd = test::random_vector(3 * M, 4);
  for (index m = 0; m < M; ++m) {
    B[m] = 4e9 * (1.5 + rnd[m]);
    B[2 * M + m] = 4e9 * (1.5 + rnd[M + m]);
    B[M + m] = 1e9 * rnd[2 * M + m];  // |bxy| < sqrt(bxx byy)
    B[3 * M + m] = 1e12;              // a penalty, as on fixed dofs
  }
  MGOptions mo;
  Multigrid mg(g, kFaceX0, 2.1e9, 0.277, mo);
  mg.set_bottom_block(B);
  Multigrid dmg(GridHierarchy::build(g, mo.coarse_nodes, world(), 64), elasticity_on(kFaceX0, 2.1e9, 0.277), mo);
  dmg.set_bottom_block(B);
  if (world().size() > 1) {
    ASSERT_TRUE(dmg.op(0).distributed());
  }
  std::vector<real> bg = test::random_vector(3 * g.nodes(), 9);
  zero_constrained(g, unsigned(kFaceX0), bg.data());
  CGOptions o;
  o.rtol = 1e-9;
  CGWorkspace ws;
  std::vector<real> ug(bg.size());
  const SolveStats sg = pcg(mg.op(0), &mg, bg.data(), ug.data(), o, ws);
  ASSERT_TRUE(sg.ok());
  // K + B on the slab: K without B, the rank's rows of B (ghost rows 0)
  const Slab& s = dmg.op(0).slab();
  const ElasticityOperator K(s, kFaceX0, 2.1e9, 0.277);
  struct KB : LinearOperator {
    const ElasticityOperator& K;
    const Slab& s;
    std::vector<real> Bl;
    KB(const ElasticityOperator& K_, const Slab& s_, const std::vector<real>& B, const GridDims& g) : K(K_), s(s_) {
      const index M = g.nx() * g.ny(), Ml = s.local.nx() * s.local.ny();
      Bl.assign(4 * Ml, 0.0);
      for (int f = 0; f < 4; ++f)
        for (index iy = s.y_begin; iy < s.y_end; ++iy)
          for (index ix = 0; ix < g.nx(); ++ix)
            Bl[f * Ml + ix + s.local.nx() * s.local_row(iy)] = ix == 0 ? 0 : B[f * M + ix + g.nx() * iy];
    }
    index size() const override { return K.size(); }
    void apply(const real* x, real* y) const override {
      K.apply(x, y);
      bottom_block_apply<real>(s.local, Bl.data(), x, operator_out(y));
    }
    void update_ghosts(real* x) const override { K.update_ghosts(x); }
  } A(K, s, B, g);
  std::vector<real> b(dmg.size()), u(dmg.size());
  global_to_local(s, bg.data(), b.data());
  K.zero_ghosts(b.data());
  o.reduction = dmg.reduction();
  const SolveStats sd = pcg(A, &dmg, b.data(), u.data(), o, ws);
  ASSERT_TRUE(sd.ok()) << dmg.describe();
  EXPECT_NEAR(sd.iterations, sg.iterations, 1) << dmg.describe();
  EXPECT_LE(max_owned_diff(s, u, ug), 1e-7 * test::max_abs(ug)) << dmg.describe();
}

TEST(CommModel, BoxHalosAndTheRankGrid) {
  const GridDims g = test::prism(64, 32, 32);
  int px = 0, py = 0;
  rank_grid(g, 1, px, py);
  EXPECT_EQ(px * py, 1);
  EXPECT_EQ(apply_halo(g, 1, 1).messages, 0);
  rank_grid(g, 8, px, py);
  EXPECT_EQ(px * py, 8);
  EXPECT_EQ(px, 8);  // 65 x 33 x 33 nodes: 8 cuts of 33 x 33 nodes beat 4 x 2 boxes (2293 ghost nodes)
  rank_grid(test::prism(64, 64, 32), 8, px, py);
  EXPECT_EQ(px * py, 8);
  EXPECT_TRUE(px == 2 || px == 4) << px;  // a square face: boxes beat slabs (3350 ghost nodes against 4290)
  const CommVolume v = apply_halo(g, 4, 2);
  EXPECT_EQ(v.messages, 8);
  EXPECT_DOUBLE_EQ(v.bytes, 24.0 * 33 * (2 * 33.0 / 2 + 2 * 65.0 / 4 + 4));
  // a Newton step: nothing on one rank; per outer iteration an S apply, a
  // V-cycle of K + B and 2 allreduces; two more S applies, 10 scalar
  // allreduces and the allreduce of the bottom-plane block per step
  const std::vector<GridDims> grids = {g, test::prism(32, 16, 16), test::prism(16, 8, 8)};
  EXPECT_EQ(newton_step_comm(grids, 1, 1, 3, 4, 6).messages, 0);
  const CommVolume s0 = newton_step_comm(grids, 1, 4, 3, 0, 6), s3 = newton_step_comm(grids, 1, 4, 3, 3, 6);
  const CommVolume s_apply = mgcg_iteration(grids, 1, 4, 3) * 6.0 + apply_halo(g, 1, 4) * 2.0;
  const CommVolume plane = allreduce_volume(4.0 * 65 * 33, 4);
  EXPECT_DOUBLE_EQ(s0.bytes, 2 * s_apply.bytes + plane.bytes);
  EXPECT_DOUBLE_EQ(s0.allreduces, 2 * s_apply.allreduces + 10 + 1);
  EXPECT_DOUBLE_EQ(s3.messages - s0.messages, 3 * (s_apply.messages + vcycle_halo(grids, 1, 4, 3).messages));
  EXPECT_DOUBLE_EQ(s3.allreduces - s0.allreduces, 3 * (s_apply.allreduces + 2));
  EXPECT_DOUBLE_EQ(plane.bytes, 2.0 * 3 / 4 * 4 * 65 * 33 * 8);
  NetworkModel net{1e-6, 1e9};
  EXPECT_DOUBLE_EQ(net.seconds({10, 1e6, 2}, 8), 10e-6 + 2 * 3e-6 + 1e-3);
}

}  // namespace tresca

int main(int argc, char** argv) {
  tresca::MpiSession mpi(argc, argv);
  ::testing::InitGoogleTest(&argc, argv);
  if (tresca::Comm::world().rank() != 0) {  // one report: rank 0's (a failure on any rank fails the run)
    auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
  }
  return RUN_ALL_TESTS();
}
