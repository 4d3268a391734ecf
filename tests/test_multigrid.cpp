// MG-preconditioned CG for K_ii against a sparse direct solve, on meshes
// whose element counts are odd (non-nested coarse grids).
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>

#include "core/solvers/cg.hpp"
#include "core/multigrid/coarse_solver.hpp"
#include "core/multigrid/interior.hpp"
#include "core/multigrid/multigrid.hpp"
#include "core/multigrid/smoothing.hpp"
#include "core/fem/assembly.hpp"
#include "core/fem/problem.hpp"
#include "kernels/vector_ops.hpp"
#include "dense_reference.hpp"
#include "test_helpers.hpp"

namespace tresca {

// chebyshev_smooth (the three-term recurrence) against the textbook
// two-term Chebyshev semi-iteration (rho_0 = 1/sigma, d_0 = Dinv r_0 / theta;
// rho_k = 1/(2 sigma - rho_{k-1}), d_k = rho_k rho_{k-1} d_{k-1} + 2 rho_k /
// delta Dinv r_k; x += d), on a small SPD
// tridiagonal matrix: every degree 1..6, from zero and from a guess entering
// in x or in r; the iterate leaves in x, and where the guess enters where
// chebyshev_entry says every step is a fused one (no residual formed)
TEST(Chebyshev, EveryDegreeAndEntryGivesTheTextbookIterate) {
  const index n = 40;
  std::vector<real> dinv(n), b = test::random_vector(n, 21), guess = test::random_vector(n, 22);
  auto A = [&](const real* x, index i) {
    return (2.5 + 0.01 * real(i)) * x[i] - (i > 0 ? x[i - 1] : 0) - (i + 1 < n ? x[i + 1] : 0);
  };
  for (index i = 0; i < n; ++i) dinv[i] = 1 / (2.5 + 0.01 * real(i));
  const real lmax = 2.2, range = 10;
  for (int degree = 1; degree <= 6; ++degree)
    for (int entry = 0; entry < 3; ++entry) {  // 0: zero guess, 1: guess in x, 2: guess in r
      // the textbook
      std::vector<real> want(n, 0.0), dk(n), rk(n);
      if (entry > 0) want = guess;
      const real lmin = lmax / range, theta = (lmax + lmin) / 2, delta = (lmax - lmin) / 2, sigma = theta / delta;
      real rho = 1 / sigma;
      for (int k = 0; k < degree; ++k) {
        for (index i = 0; i < n; ++i) rk[i] = b[i] - A(want.data(), i);
        const real rho_new = k == 0 ? rho : 1 / (2 * sigma - rho);
        for (index i = 0; i < n; ++i)
          dk[i] = (k == 0 ? 0 : rho_new * rho * dk[i]) + (k == 0 ? 1 / theta : 2 * rho_new / delta) * dinv[i] * rk[i];
        rho = rho_new;
        for (index i = 0; i < n; ++i) want[i] += dk[i];
      }
      // chebyshev_smooth
      std::vector<real> x(n, std::nan("")), r(n, std::nan(""));
      real* in = entry == 1 ? x.data() : entry == 2 ? r.data() : nullptr;
      if (in) std::copy(guess.begin(), guess.end(), in);
      int residuals = 0, steps = 0;
      chebyshev_smooth<real>(
          n, lmax, range, degree, entry == 0, dinv.data(), b.data(), x.data(), r.data(),
          [&](real* from, real* to) {
            ++residuals;
            for (index i = 0; i < n; ++i) to[i] = b[i] - A(from, i);
          },
          [&](real* from, real* to, real s, real t, bool from_zero) {
            ++steps;
            ASSERT_NE(from, to);
            // the three-term form: `to` holds the iterate before `from`,
            // read unless that is zero (NaN here where no step wrote it)
            for (index i = 0; i < n; ++i)
              to[i] = from[i] + t * dinv[i] * (b[i] - A(from, i)) +
                      (s == 0 ? 0 : s * (from_zero ? from[i] : from[i] - to[i]));
          },
          in);
      for (index i = 0; i < n; ++i)
        ASSERT_NEAR(x[i], want[i], 1e-13 * (1 + std::abs(want[i]))) << "degree " << degree << " entry " << entry;
      const bool fused_entry = entry == 0 || in == chebyshev_entry(degree, x.data(), r.data());
      EXPECT_EQ(residuals, fused_entry ? 0 : 1) << "degree " << degree << " entry " << entry;
      EXPECT_EQ(steps, degree - (entry == 0 || !fused_entry ? 1 : 0)) << "degree " << degree << " entry " << entry;
    }
}

// lanczos_lmax against the largest eigenvalue of D^{-1}K from a dense
// symmetric eigensolver (of D^{-1/2} K D^{-1/2}, K assembled element by
// element), in double and in float: its Ritz value lies below the true one
// and close to it, the float run within float rounding of the double one,
// and a multigrid's levels get the estimate of the V-cycle's precision
TEST(Lanczos, EstimatesTheLargestEigenvalueOfTheJacobiScaledOperatorInBothPrecisions) {
  const Problem P = make_problem(spec_for_dims(7, 4, 5));
  const ElasticityOperator K(P.grid, P.interior_faces, P.spec.E, P.spec.nu);
  const index n = K.size();
  const real exact = jacobi_scaled_lmax(K);
  ASSERT_GT(exact, 2.1);  // (above the estimate's floor of 2)
  const auto start = test::random_vector(n, 31);
  const Field<real> d = K.diagonal();
  auto estimate = [&](auto zero) {
    using T = decltype(zero);
    Field<T> dinv = Field<T>(std::size_t(n)), r = Field<T>(std::size_t(n));
    reciprocal_or_zero<T>(n, d.data(), dinv.data());
    for (index i = 0; i < n; ++i) r[i] = T(start[i]);
    return lanczos_lmax<T>(n, [&](T* p, T* q) { K.apply(p, q); }, dinv, std::move(r)) / 1.15;
  };
  const real lmax = estimate(0.0), lmax_f = estimate(0.0f);
  EXPECT_LE(lmax, exact * (1 + 1e-12));
  EXPECT_GE(lmax, 0.999 * exact);  // (4.5e-6 below it when written)
  EXPECT_NEAR(lmax_f, lmax, 1e-6 * lmax);  // (3.7e-9 apart when written)
  // no free entry to start from: no step, the floor
  EXPECT_EQ(lanczos_lmax<real>(n, [&](real* p, real* q) { K.apply(p, q); }, K.diagonal(), Field<real>(std::size_t(n))),
            1.15 * 2);

  const Problem Q = make_problem(spec_for_dims(16, 8, 8));
  real level_lmax[2][8] = {};
  int levels = 0;
  for (Precision prec : {Precision::double_precision, Precision::single_precision}) {
    MGOptions mo;
    mo.precision = prec;
    mo.coarse_nodes = 60;
    const Multigrid mg(Q.grid, Q.interior_faces, Q.spec.E, Q.spec.nu, mo);
    levels = mg.num_levels();
    ASSERT_LE(levels, 8);
    for (int l = 0; l + 1 < levels; ++l) level_lmax[prec == Precision::single_precision][l] = mg.lmax(l);
  }
  ASSERT_GE(levels, 3);
  for (int l = 0; l + 1 < levels; ++l) {
    EXPECT_GT(level_lmax[0][l], 2.3) << "level " << l;
    EXPECT_NE(level_lmax[0][l], level_lmax[1][l]) << "level " << l << ": float and double estimates should round apart";
    EXPECT_NEAR(level_lmax[1][l], level_lmax[0][l], 1e-5 * level_lmax[0][l]) << "level " << l;
  }
}

TEST(MultigridCG, MatchesSparseDirectSolveOnOddMeshes) {
  const index sizes[][3] = {{7, 3, 5}, {9, 5, 5}, {23, 12, 12}};
  for (auto& s : sizes) {
    const Problem P = make_problem(spec_for_dims(s[0], s[1], s[2]));
    MGOptions mo;
    mo.coarse_nodes = 60;  // force several levels even on small meshes
    Multigrid mg(P.grid, P.interior_faces, P.spec.E, P.spec.nu, mo);
    ASSERT_GE(mg.num_levels(), 2);
    const InteriorSolution sol = solve_interior_elasticity(P, mg, 1e-12);
    const SolveStats& st = sol.stats;
    const Field<real>& u = sol.u;
    ASSERT_TRUE(st.ok()) << to_string(st.reason);
    EXPECT_LT(sol.relative_residual, 1e-11);
    const Field<real> load = whole_load(P);
  std::vector<real> b(load.begin(), load.end());
    zero_constrained(P.grid, P.interior_faces, b.data());
    EXPECT_LT(st.iterations, 40);
    Eigen::SimplicialLDLT<SparseMatrix> ldlt(assemble(mg.op(0)));
    Eigen::Map<const Eigen::VectorXd> bv(b.data(), P.dofs());
    Eigen::VectorXd ud = ldlt.solve(bv);
    real err = 0, scale = 0;
    for (index i = 0; i < P.dofs(); ++i) {
      err = std::max(err, std::abs(u[i] - ud[i]));
      scale = std::max(scale, std::abs(ud[i]));
    }
    EXPECT_LT(err, 1e-9 * scale) << s[0] << "x" << s[1] << "x" << s[2];
  }
}

// The coarsest level's direct solve (coarse_solver.hpp): (K + B)^-1 b
// against Eigen's sparse LDLT of the assembled K + B, for K alone and three
// bottom blocks in turn (the last with the Newton step's penalties, 1e4
// times K's diagonal), on both of its paths (the face's Schur complement
// kept dense; the whole refactorised), with x = 0 clamped (the face leaves
// its nodes out) and with the bottom face clamped too (no face at all)
TEST(CoarseSolver, SolvesKPlusEachBottomBlockLikeASparseLDLTOnBothPaths) {
  for (unsigned faces : {unsigned(kFaceX0), unsigned(kFaceX0 | kFaceZ0)})
    for (index max_dense : {CoarseSolver::kMaxDenseFace, index(0)}) {
      ElasticityOperator A(test::prism(8, 4, 4), faces, 2.1e9, 0.277);
      const GridDims& g = A.grid();
      const index M = g.nx() * g.ny(), N = g.nodes();
      const SparseMatrix K = assemble_stiffness(A);
      const std::vector<index> face = bottom_block_dofs(g, faces);
      EXPECT_EQ(index(face.size()), faces & kFaceZ0 ? 0 : 3 * (M - g.ny()));
      CoarseSolver coarse(max_dense);
      coarse.factor(K, face);
      EXPECT_EQ(coarse.dense_face(), index(face.size()) <= max_dense);
      const std::vector<real> r = test::random_vector(4 * M, 31);
      for (int k = 0; k < 4; ++k) {
        std::vector<real> B;  // k = 0: none
        if (k > 0) {
          B.assign(4 * M, 0.0);
          const real scale = k == 3 ? 1e4 : k;
          for (index n = 0; n < M; ++n) {
            const real bxx = scale * (1 + r[n]) * K.coeff(n, n);
            const real byy = scale * (1 + r[2 * M + n]) * K.coeff(N + n, N + n);
            B[n] = bxx;
            B[M + n] = 0.5 * r[M + n] * std::sqrt(bxx * byy);  // (|r| < 1: each 2x2 block positive)
            B[2 * M + n] = byy;
            B[3 * M + n] = scale * (1 + r[3 * M + n]) * K.coeff(2 * N + n, 2 * N + n);
          }
        }
        A.set_bottom_block(B);  // (zero on constrained nodes)
        if (k > 0) coarse.update(assemble_bottom_block(g, A.bottom_block().to_vector()));
        // b = (K + B) u for u of entries in [-1, 1] (so that K's identity
        // rows on clamped dofs do not dominate the norms)
        const SparseMatrix KB = assemble(A);
        const std::vector<real> uv = test::random_vector(A.size(), 32 + k);
        const Eigen::VectorXd u = Eigen::Map<const Eigen::VectorXd>(uv.data(), A.size());
        const Eigen::VectorXd b = KB * u;
        Eigen::VectorXd x;
        coarse.solve(b, x);
        const Eigen::VectorXd xr = Eigen::SimplicialLDLT<SparseMatrix>(KB).solve(b);
        EXPECT_LT((xr - u).norm(), 1e-13 * u.norm()) << "the reference, block " << k;
        EXPECT_LT((x - u).norm(), 1e-13 * u.norm())
            << "faces " << faces << ", max_dense " << max_dense << ", block " << k;
        EXPECT_LT((KB * x - b).norm(), 1e-14 * b.norm())
            << "faces " << faces << ", max_dense " << max_dense << ", block " << k;
      }
      if (coarse.dense_face()) {  // a B off the face is refused where only the face is kept
        SparseMatrix off(A.size(), A.size());
        off.insert(M + 1, M + 1) = 1.0;  // (node (1, 0, 1), above the bottom plane)
        EXPECT_THROW(coarse.update(off), std::invalid_argument);
      }
    }
}

// Solvers given the same K and face share one factor of K (coarse_solver.hpp:
// nested iteration's meshes end on the same coarsest grid); each keeps its
// own bottom block, and a K that differs in one entry is factorised anew.
// (A material no other test uses: the few most recent factors outlive their
// solvers, so a K factorised by an earlier test in this process would be reused.)
TEST(CoarseSolver, SharesTheFactorOfTheSameKAndFaceOnly) {
  ElasticityOperator A(test::prism(8, 4, 4), kFaceX0, 3.7e9, 0.2345);
  const GridDims& g = A.grid();
  const index M = g.nx() * g.ny();
  const SparseMatrix K = assemble_stiffness(A);
  const std::vector<index> face = bottom_block_dofs(g, kFaceX0);
  const CoarseSolver::Shared before = CoarseSolver::shared_factors();
  CoarseSolver a, b;
  a.factor(K, face);
  b.factor(K, face);
  CoarseSolver::Shared now = CoarseSolver::shared_factors();
  EXPECT_EQ(now.made - before.made, 1);
  EXPECT_EQ(now.reused - before.reused, 1);
  // a gets a bottom block, b keeps K alone: each solves its own
  std::vector<real> B(4 * M, 0.0);
  for (index n = 0; n < M; ++n) B[n] = B[2 * M + n] = B[3 * M + n] = 1e3 * K.coeff(n, n);
  A.set_bottom_block(B);
  a.update(assemble_bottom_block(g, A.bottom_block().to_vector()));
  const SparseMatrix KB = assemble(A);
  const std::vector<real> uv = test::random_vector(A.size(), 41);
  const Eigen::VectorXd u = Eigen::Map<const Eigen::VectorXd>(uv.data(), A.size());
  Eigen::VectorXd xa, xb;
  a.solve(KB * u, xa);
  b.solve(K.selfadjointView<Eigen::Lower>() * u, xb);
  EXPECT_LT((xa - u).norm(), 1e-13 * u.norm());
  EXPECT_LT((xb - u).norm(), 1e-13 * u.norm());
  // one entry of K changed (kept symmetric: the lower triangle is read)
  SparseMatrix K2 = K;
  K2.coeffRef(5, 5) *= 1 + 1e-15;
  CoarseSolver c;
  c.factor(K2, face);
  now = CoarseSolver::shared_factors();
  EXPECT_EQ(now.made - before.made, 2);
  EXPECT_EQ(now.reused - before.reused, 1);
}

TEST(MultigridCG, SinglePrecisionVCycleKeepsIterationsAndAccuracy) {
  // the V-cycle in float preconditions a double CG: same iteration count (+-1)
  // and the same attainable accuracy as the double V-cycle, odd mesh included
  for (int level : {5, 7})
    for (bool odd : {false, true}) {
      const Problem P = odd ? make_problem(spec_for_dims(23, 11, 13)) : make_problem(spec_for_level(level));
      int its[2];
      Field<real> u[2];
      for (int k = 0; k < 2; ++k) {
        MGOptions mo;
        mo.precision = k ? Precision::single_precision : Precision::double_precision;
        Multigrid mg(P.grid, P.interior_faces, P.spec.E, P.spec.nu, mo);
        const InteriorSolution sol = solve_interior_elasticity(P, mg, 1e-12);
        ASSERT_TRUE(sol.stats.ok()) << to_string(sol.stats.reason);
        EXPECT_LT(sol.relative_residual, 1e-12);
        its[k] = sol.stats.iterations;
        u[k] = sol.u;
      }
      EXPECT_LE(std::abs(its[1] - its[0]), 1) << "level " << level << (odd ? " (23x11x13)" : "");
      EXPECT_LT(test::max_abs_diff(u[0], u[1]), 1e-10 * test::max_abs(u[0]));
    }
}

// A V-cycle in float gives CG its float vectors directly (operator.hpp's
// works_in_float): apply_in_float is apply rounded, bit for bit, and CG
// through it takes the same iterates, bit for bit, as CG through apply()
// (the preconditioner seen as a double operator only); odd mesh included
TEST(MultigridCG, AFloatVCycleTakesTheCGsFloatVectorsWithTheSameIterates) {
  struct DoubleOnly : LinearOperator {  // the multigrid without its float interface
    const Multigrid& mg;
    explicit DoubleOnly(const Multigrid& m) : mg(m) {}
    index size() const override { return mg.size(); }
    void apply(const real* x, real* y) const override { mg.apply(x, y); }
  };
  for (const Problem& P : {make_problem(spec_for_level(5)), make_problem(spec_for_dims(23, 11, 13))}) {
    const index n = P.dofs();
    MGOptions mo;
    mo.precision = Precision::single_precision;
    const Multigrid mg(P.grid, P.interior_faces, P.spec.E, P.spec.nu, mo);
    ASSERT_TRUE(mg.works_in_float());
    auto r = test::random_vector(n, 41);
    zero_constrained(P.grid, P.interior_faces, r.data());
    std::vector<real> z(n);
    mg.apply(r.data(), z.data());
    const std::vector<float> rf(r.begin(), r.end());
    std::vector<float> zf(n, std::nanf(""));
    mg.apply_in_float(rf.data(), zf.data());
    for (index i = 0; i < n; ++i) ASSERT_EQ(zf[i], float(z[i])) << "entry " << i;

    const ElasticityOperator K(P.grid, P.interior_faces, P.spec.E, P.spec.nu);
    CGOptions o;
    o.rtol = 1e-10;
    SolveStats st[2];
    std::vector<real> u[2];
    for (int k = 0; k < 2; ++k) {
      CGWorkspace ws;
      u[k].assign(n, 0);
      const DoubleOnly plain(mg);
      st[k] = pcg(K, k ? static_cast<const LinearOperator*>(&plain) : &mg, r.data(), u[k].data(), o, ws);
      ASSERT_TRUE(st[k].ok()) << to_string(st[k].reason);
      EXPECT_EQ(ws.z.size(), k ? std::size_t(n) : 0u);  // (no double z where M works in float)
    }
    EXPECT_EQ(st[0].iterations, st[1].iterations);
    EXPECT_GT(st[0].iterations, 3);
    EXPECT_EQ(st[0].residual, st[1].residual);
    for (index i = 0; i < n; ++i) ASSERT_EQ(u[0][i], u[1][i]) << "entry " << i;
  }
  // a V-cycle in double has no float interface
  const Problem P = make_problem(spec_for_level(3));
  MGOptions mo;
  mo.precision = Precision::double_precision;
  const Multigrid md(P.grid, P.interior_faces, P.spec.E, P.spec.nu, mo);
  EXPECT_FALSE(md.works_in_float());
  std::vector<float> a(P.dofs()), b(P.dofs());
  EXPECT_THROW(md.apply_in_float(a.data(), b.data()), std::logic_error);
}

TEST(MultigridVCycle, IsSymmetricInBothPrecisions) {
  // CG needs a symmetric preconditioner: |x^T M y - y^T M x| small relative to
  // |x||M y| (float rounding leaves ~1e-7 in single precision)
  const Problem P = make_problem(spec_for_dims(13, 7, 9));
  for (Precision prec : {Precision::double_precision, Precision::single_precision}) {
    MGOptions mo;
    mo.precision = prec;
    mo.coarse_nodes = 60;
    Multigrid mg(P.grid, P.interior_faces, P.spec.E, P.spec.nu, mo);
    auto x = test::random_vector(P.dofs(), 21), y = test::random_vector(P.dofs(), 22);
    zero_constrained(P.grid, P.interior_faces, x.data());
    zero_constrained(P.grid, P.interior_faces, y.data());
    std::vector<real> Mx(P.dofs()), My(P.dofs());
    mg.apply(x.data(), Mx.data());
    mg.apply(y.data(), My.data());
    const real a = dot(P.dofs(), x.data(), My.data()), b = dot(P.dofs(), y.data(), Mx.data());
    const real scale = norm2(P.dofs(), x.data()) * norm2(P.dofs(), My.data());
    EXPECT_LT(std::abs(a - b), (prec == Precision::single_precision ? 1e-5 : 1e-12) * scale) << to_string(prec);
  }
}

TEST(MultigridCG, HierarchyIsSharedAndTheOperatorComesFromItsDescription) {
  // one GridHierarchy, two operators: K_ii of the benchmark, and K with only
  // x = 0 fixed, another material and a bottom-face block (the Newton-step
  // preconditioner's kind); both preconditioned CG solves converge fast
  const Problem P = make_problem(spec_for_dims(17, 9, 9));
  MGOptions mo;
  mo.coarse_nodes = 100;
  const auto grids = GridHierarchy::build(P.grid, mo.coarse_nodes);
  ASSERT_GE(grids->levels.size(), 3u);
  Multigrid a(grids, elasticity_on(P.interior_faces, P.spec.E, P.spec.nu), mo);
  Multigrid b(grids, elasticity_on(kFaceX0, 7e10, 0.33), mo);
  EXPECT_EQ(a.hierarchy().get(), b.hierarchy().get());
  const index M = P.grid.nx() * P.grid.ny();
  std::vector<real> B(4 * M, 0.0);
  for (index n = 0; n < M; ++n) B[n] = B[2 * M + n] = B[3 * M + n] = 1e9;
  b.set_bottom_block(B);
  for (Multigrid* mg : {&a, &b}) {
    auto rhs = test::random_vector(P.dofs(), 41);
    zero_constrained(mg->op(0).grid(), mg->op(0).faces(), rhs.data());
    std::vector<real> x(P.dofs());
    CGOptions o;
    o.rtol = 1e-10;
    CGWorkspace ws;
    const SolveStats st = pcg(mg->op(0), mg, rhs.data(), x.data(), o, ws);
    ASSERT_TRUE(st.ok()) << to_string(st.reason);
    EXPECT_LT(st.iterations, 20);
    std::vector<real> r(P.dofs());
    mg->op(0).residual(rhs.data(), x.data(), r.data());
    EXPECT_LT(norm2(P.dofs(), r.data()), 1e-9 * norm2(P.dofs(), rhs.data()));
  }
  // an operator that does not live on the hierarchy's grids is refused
  const GridDims other = test::prism(5, 3, 3);
  EXPECT_THROW(Multigrid(grids, [&](const Slab&) { return ElasticityOperator(other, kFaceX0, 1, 0.3); }, mo),
               std::invalid_argument);
}

TEST(MultigridVCycle, OneBuiltLikeAnotherSharesItsWorkVectorsAndLeavesItsAnswersAlone) {
  // the Newton step's K + B preconditioner is built like the K_ii solver's
  // multigrid: it shares the V-cycle's work vectors (x, b, r, d on every
  // level) instead of making its own, and the two V-cycles, in turn, give
  // bit for bit what each gives alone
  const Problem P = make_problem(spec_for_dims(64, 32, 32));  // level-0 vectors of 2.4 MiB (float): counted blocks
  for (Precision prec : {Precision::single_precision, Precision::double_precision}) {
    MGOptions mo;
    mo.precision = prec;
    mo.coarse_nodes = 400;
    const auto grids = GridHierarchy::build(P.grid, mo.coarse_nodes);
    Multigrid a(grids, elasticity_on(P.interior_faces, P.spec.E, P.spec.nu), mo);
    const double before = block_reuse(Space::host).live_bytes;
    Multigrid b(grids, elasticity_on(kFaceX0, P.spec.E, P.spec.nu), mo, &a);
    const double grown = block_reuse(Space::host).live_bytes - before;
    // b's own level-0 vectors: dinv alone (made in place of 5 with x, b, r, d)
    const double vector = double(P.dofs()) * (prec == Precision::single_precision ? 4 : 8);
    EXPECT_LT(grown, 1.5 * vector) << to_string(prec);
    const index M = P.grid.nx() * P.grid.ny();
    std::vector<real> B(4 * M, 0.0);
    for (index n = 0; n < M; ++n) B[n] = B[2 * M + n] = B[3 * M + n] = 1e9;
    b.set_bottom_block(B);

    auto ra = test::random_vector(P.dofs(), 51), rb = test::random_vector(P.dofs(), 52);
    zero_constrained(P.grid, P.interior_faces, ra.data());
    zero_constrained(P.grid, kFaceX0, rb.data());
    std::vector<real> za(P.dofs()), zb(P.dofs()), za2(P.dofs()), zb2(P.dofs());
    a.apply(ra.data(), za.data());
    b.apply(rb.data(), zb.data());
    a.apply(ra.data(), za2.data());
    b.apply(rb.data(), zb2.data());
    EXPECT_EQ(za, za2) << to_string(prec);
    EXPECT_EQ(zb, zb2) << to_string(prec);
    EXPECT_GT(test::max_abs(za), 0);
    EXPECT_GT(test::max_abs_diff(za, zb), 1e-3 * test::max_abs(za)) << "two operators, two answers";
  }
}

TEST(MultigridVCycle, RestrictedToSomeEntriesItIsTheFullVCycleScatteredAndGathered) {
  // apply_at(at, r, z) = E^T M E r, E placing r at the entries `at`: the
  // same numbers as the full V-cycle of the scattered vector, gathered,
  // bit for bit, and in turn with the full apply (they share work vectors)
  const Problem P = make_problem(spec_for_dims(19, 9, 11));
  const index nx = P.grid.nx(), N = P.grid.nodes();
  std::vector<index> at_host;  // the bottom face's nodes off x = 0, 3 components
  for (int a = 0; a < 3; ++a)
    for (index iy = 0; iy < P.grid.ny(); ++iy)
      for (index ix = 1; ix < nx; ++ix) at_host.push_back(a * N + P.grid.node(ix, iy, 0));
  const index m = index(at_host.size());
  Field<index> at(at_host.begin(), at_host.end());
  at.move_to(launch_space());
  for (Precision prec : {Precision::single_precision, Precision::double_precision}) {
    MGOptions mo;
    mo.precision = prec;
    mo.coarse_nodes = 100;
    Multigrid mg(P.grid, kFaceX0, P.spec.E, P.spec.nu, mo);
    const auto r = test::random_vector(m, 61);
    std::vector<real> full(P.dofs(), 0.0), full_out(P.dofs()), z(m), z_full(m);
    for (index k = 0; k < m; ++k) full[at_host[k]] = r[k];
    mg.apply(full.data(), full_out.data());
    for (index k = 0; k < m; ++k) z_full[k] = full_out[at_host[k]];
    mg.apply_at(at, r.data(), z.data());
    EXPECT_EQ(z, z_full) << to_string(prec);
    EXPECT_GT(test::max_abs(z), 0);
    // a full apply of another vector in between leaves apply_at's answer alone
    const auto other = test::random_vector(P.dofs(), 62);
    mg.apply(other.data(), full_out.data());
    std::vector<real> z2(m);
    mg.apply_at(at, r.data(), z2.data());
    EXPECT_EQ(z, z2) << to_string(prec);
  }
}

TEST(MultigridCG, IterationCountIsMeshIndependent) {
  // coarse_nodes = 100 makes every one of these a genuine multilevel cycle
  int its[3];
  for (int level = 4; level <= 6; ++level) {
    const Problem P = make_problem(spec_for_level(level));
    MGOptions mo;
    mo.coarse_nodes = 100;
    Multigrid mg(P.grid, P.interior_faces, P.spec.E, P.spec.nu, mo);
    ASSERT_GE(mg.num_levels(), 3);
    const InteriorSolution sol = solve_interior_elasticity(P, mg, 1e-10);
    ASSERT_TRUE(sol.stats.ok());
    EXPECT_LT(sol.relative_residual, 1e-10);
    its[level - 4] = sol.stats.iterations;
  }
  EXPECT_LE(its[2], its[0] + 3);
  EXPECT_LE(its[1], its[0] + 3);
  EXPECT_LT(its[2], 20);
}

TEST(MultigridCG, SemiCoarseningKeepsAnisotropicMeshesFast) {
  // full coarsening of flat or elongated bricks needed 200-330 iterations here
  const index sizes[][3] = {{256, 2, 2}, {8, 8, 200}, {200, 100, 2}};
  for (auto& s : sizes) {
    const Problem P = make_problem(spec_for_dims(s[0], s[1], s[2]));
    Multigrid mg(P.grid, P.interior_faces, P.spec.E, P.spec.nu);
    const InteriorSolution sol = solve_interior_elasticity(P, mg, 1e-10);
    ASSERT_TRUE(sol.stats.ok());
    EXPECT_LT(sol.stats.iterations, 15) << s[0] << "x" << s[1] << "x" << s[2] << ": " << mg.describe();
    EXPECT_LT(sol.relative_residual, 1e-10);
  }
}

TEST(Coarsening, SaysWhereAThinPlateOfWideElementsLeavesAnisotropyBehind) {
  // a plate 2 x 1 x 0.02 m of 16x8x2 elements: z coarsens to one element
  // (0.02 m thick) while x and y keep 0.125 m: 6.25, and the contact
  // solve's boundary V-cycle stalls (RESULTS.md §0ze); with 32x16x4, 3.125
  // (it converges); the benchmark's levels, bars, plates thick across their
  // elements and the semi-coarsened meshes above leave none
  auto plate = [](index ex, index ey, index ez, real lz) {
    ProblemSpec s = spec_for_dims(ex, ey, ez);
    s.lz = lz;
    return unresolved_anisotropy(grid_of(s));
  };
  EXPECT_NEAR(plate(16, 8, 2, 0.02), 0.125 / 0.02, 1e-9);
  EXPECT_NEAR(plate(32, 16, 4, 0.02), 0.0625 / 0.02, 1e-9);
  EXPECT_NEAR(plate(16, 8, 2, 0.01), 0.125 / 0.01, 1e-9);
  for (int level = 0; level <= 12; ++level) EXPECT_LT(unresolved_anisotropy(grid_of(spec_for_level(level))), 1.5);
  const index sizes[][3] = {{100, 1, 1}, {1000, 2, 1}, {64, 32, 1}, {256, 2, 2}, {8, 8, 200}, {200, 100, 2}};
  for (auto& e : sizes)
    EXPECT_LT(unresolved_anisotropy(grid_of(spec_for_dims(e[0], e[1], e[2]))), 4) << e[0] << "x" << e[1] << "x" << e[2];
  // the plate's first coarsening halves its thickness's elements alone
  ProblemSpec thin = spec_for_dims(16, 8, 2);
  thin.lz = 0.02;
  const std::vector<GridDims> levels = coarsening(grid_of(thin));
  ASSERT_GE(levels.size(), 2u);
  EXPECT_EQ(levels[1].ez, 1);
  EXPECT_EQ(levels[1].ex, 16);
}

TEST(CG, ReportsMaxIterationsInsteadOfLooping) {
  const Problem P = make_problem(spec_for_level(4));
  ElasticityOperator A(P.grid, P.interior_faces, P.spec.E, P.spec.nu);
  const Field<real> load = whole_load(P);
  std::vector<real> b(load.begin(), load.end()), u(P.dofs());
  zero_constrained(P.grid, P.interior_faces, b.data());
  CGOptions o;
  o.rtol = 1e-14;
  o.max_iterations = 5;
  CGWorkspace ws;
  const SolveStats st = pcg(A, nullptr, b.data(), u.data(), o, ws);
  EXPECT_EQ(st.reason, SolveReason::max_iterations);
  EXPECT_EQ(st.iterations, 5);
}

TEST(CG, SideProductIsBOfTheSolutionOrAddsOntoTheCallersOne) {
  // A: the 1D Laplacian (n = 40), B x = (sum of x, x[0] - x[n-1]): the
  // side product of the solution, set or (side_adds) added onto what the
  // caller put there, against B applied to the solution afterwards
  const index n = 40;
  class Laplace1D : public LinearOperatorWithSide {
   public:
    index size() const override { return n; }
    index side_size() const override { return 2; }
    void apply(const real* x, real* y) const override {
      for (index i = 0; i < n; ++i) y[i] = 2 * x[i] - (i > 0 ? x[i - 1] : 0) - (i + 1 < n ? x[i + 1] : 0);
    }
    void apply(const real* x, real* y, real* s) const override {
      apply(x, y);
      s[0] = std::accumulate(x, x + n, real(0));
      s[1] = x[0] - x[n - 1];
    }
  } A;
  const auto b = test::random_vector(n, 71);
  for (bool adds : {false, true})
    for (bool zero_guess : {true, false}) {
      std::vector<real> x(n, 0.0), side = {3.0, -5.0};
      if (!zero_guess) x = test::random_vector(n, 72);
      CGOptions o;
      o.rtol = 1e-13;
      o.side_adds = adds;
      o.zero_initial_guess = zero_guess;
      CGWorkspace ws;
      const SolveStats st = pcg(A, nullptr, b.data(), x.data(), side.data(), o, ws);
      ASSERT_TRUE(st.ok()) << to_string(st.reason);
      std::vector<real> Ax(n), Bx(2);
      A.apply(x.data(), Ax.data(), Bx.data());
      const std::vector<real> want = adds ? std::vector<real>{3.0 + Bx[0], -5.0 + Bx[1]} : Bx;
      for (int k = 0; k < 2; ++k)
        EXPECT_NEAR(side[k], want[k], 1e-9 * (1 + std::abs(Bx[k]))) << "adds " << adds << " zero guess " << zero_guess;
    }
}

TEST(CG, ReportsNonFiniteInput) {
  const Problem P = make_problem(spec_for_dims(3, 2, 2));
  ElasticityOperator A(P.grid, P.interior_faces, P.spec.E, P.spec.nu);
  std::vector<real> b(P.dofs(), 1.0), u(P.dofs());
  b[5] = std::numeric_limits<real>::quiet_NaN();
  CGWorkspace ws;
  const SolveStats st = pcg(A, nullptr, b.data(), u.data(), CGOptions{}, ws);
  EXPECT_EQ(st.reason, SolveReason::non_finite);
}

}  // namespace tresca
