// The blocked, parallel vector kernels against their serial _ref twins on
// awkward lengths (below, at and across the block size), and their bitwise
// independence of the thread count.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <limits>
#include <string>

#include "core/fem/problem.hpp"
#include "core/util/profile.hpp"
#include "kernels/launch.hpp"
#include "kernels/vector_ops.hpp"
#include "test_helpers.hpp"

namespace tresca {

namespace {
const index kLengths[] = {1, 7, 597, kDotBlock - 1, kDotBlock, kDotBlock + 1, 5 * kDotBlock + 43, 100003};
}

TEST(VectorOps, DotAndCgUpdateMatchReferenceOnAwkwardLengths) {
  for (index n : kLengths) {
    const auto x = test::random_vector(n, 1), y = test::random_vector(n, 2);
    const real d = dot(n, x.data(), y.data()), dr = dot_ref(n, x.data(), y.data());
    EXPECT_NEAR(d, dr, 1e-13 * double(n)) << "n = " << n;
    auto x1 = test::random_vector(n, 3), r1 = test::random_vector(n, 4);
    auto x2 = x1, r2 = r1;
    const real rr = cg_update(n, 0.37, x.data(), y.data(), x1.data(), r1.data());
    const real rr_ref = cg_update_ref(n, 0.37, x.data(), y.data(), x2.data(), r2.data());
    EXPECT_NEAR(rr, rr_ref, 1e-13 * rr_ref) << "n = " << n;
    EXPECT_LT(test::max_abs_diff(x1, x2), 1e-15);
    EXPECT_LT(test::max_abs_diff(r1, r2), 1e-15);
  }
}

// the CG's fused kernels (cg.cpp), for a preconditioner that works in
// float and for its start: each the same bits as the unfused kernels it
// replaces (dot, xpay and cg_update on the float values widened; a copy or
// triad and a dot), and each float copy is its vector rounded
TEST(VectorOps, CgFusedKernelsAreTheirUnfusedFormsBitForBit) {
  for (index n : kLengths) {
    const auto r = test::random_vector(n, 11), a = test::random_vector(n, 12), b = test::random_vector(n, 13);
    std::vector<float> zf(n);
    std::vector<real> z(n);
    for (index i = 0; i < n; ++i) z[i] = real(zf[i] = float(a[i]));
    EXPECT_EQ(dot(n, r.data(), zf.data()), dot(n, r.data(), z.data())) << "n = " << n;
    auto p1 = b, p2 = b;
    xpay(n, zf.data(), -0.43, p1.data());
    xpay(n, z.data(), -0.43, p2.data());
    for (index i = 0; i < n; ++i) ASSERT_EQ(p1[i], p2[i]) << "n = " << n << ", entry " << i;
    auto x1 = a, r1 = r, x2 = a, r2 = r;
    std::vector<float> r_low(n, std::nanf(""));
    EXPECT_EQ(cg_update(n, 0.37, b.data(), z.data(), x1.data(), r1.data(), r_low.data()),
              cg_update(n, 0.37, b.data(), z.data(), x2.data(), r2.data()))
        << "n = " << n;
    for (index i = 0; i < n; ++i) {
      ASSERT_EQ(x1[i], x2[i]) << "n = " << n << ", entry " << i;
      ASSERT_EQ(r1[i], r2[i]) << "n = " << n << ", entry " << i;
      ASSERT_EQ(r_low[i], float(r2[i])) << "n = " << n << ", entry " << i;
    }
    // CG's start: r = b - q or b, its float copy where asked, and r.r with dot's bits
    for (bool with_q : {false, true})
      for (bool low : {false, true}) {
        std::vector<real> r3(n, std::nan(""));
        std::fill(r_low.begin(), r_low.end(), std::nanf(""));
        const real rr = cg_start(n, b.data(), with_q ? a.data() : nullptr, r3.data(), low ? r_low.data() : nullptr);
        for (index i = 0; i < n; ++i) {
          ASSERT_EQ(r3[i], with_q ? b[i] - a[i] : b[i]) << "n = " << n << ", entry " << i;
          ASSERT_TRUE(low ? r_low[i] == float(r3[i]) : std::isnan(r_low[i])) << "n = " << n << ", entry " << i;
        }
        EXPECT_EQ(rr, dot(n, r3.data(), r3.data())) << "n = " << n;
      }
    // CG's first direction: p = z widened, and r.p with dot's bits
    std::vector<real> p3(n, std::nan(""));
    const real rp = cg_first_direction(n, r.data(), zf.data(), p3.data());
    for (index i = 0; i < n; ++i) ASSERT_EQ(p3[i], z[i]) << "n = " << n << ", entry " << i;
    EXPECT_EQ(rp, dot(n, r.data(), z.data())) << "n = " << n;
  }
}

// the Lanczos estimate's kernels (double and float vectors, sums in double)
// against their _ref twins and the plain loops they fuse
TEST(VectorOps, JacobiCgStepsMatchReferenceInBothPrecisions) {
  auto check = [](auto zero, real tol) {
    using T = decltype(zero);
    for (index n : kLengths) {
      std::vector<T> q(n), dinv(n), r1(n), p1(n), x(n);
      const auto a = test::random_vector(n, 7), b = test::random_vector(n, 8), c = test::random_vector(n, 9),
                 e = test::random_vector(n, 10);
      for (index i = 0; i < n; ++i) {
        q[i] = T(a[i]);
        dinv[i] = T(1.5 + b[i]);
        r1[i] = T(c[i]);
        p1[i] = T(e[i]);
        x[i] = T(b[i]);
      }
      auto r2 = r1, p2 = p1;
      const real s = jacobi_cg_update<T>(n, T(0.37), q.data(), dinv.data(), r1.data());
      const real s_ref = jacobi_cg_update_ref<T>(n, T(0.37), q.data(), dinv.data(), r2.data());
      EXPECT_NEAR(s, s_ref, tol * std::abs(s_ref)) << "n = " << n;
      real plain = 0;
      for (index i = 0; i < n; ++i) plain += real(r2[i]) * real(dinv[i]) * real(r2[i]);
      EXPECT_NEAR(s, plain, tol * std::abs(plain)) << "n = " << n;
      for (index i = 0; i < n; ++i) ASSERT_EQ(r1[i], r2[i]) << "n = " << n << ", entry " << i;
      jacobi_xpay<T>(n, dinv.data(), r1.data(), T(-0.6), p1.data());
      for (index i = 0; i < n; ++i)
        ASSERT_NEAR(p1[i], dinv[i] * r2[i] - T(0.6) * p2[i], 4 * std::numeric_limits<T>::epsilon() * 4) << "n = " << n;
      const real d = dot<T>(n, q.data(), x.data()), d_ref = dot_ref<T>(n, q.data(), x.data());
      EXPECT_NEAR(d, d_ref, tol * double(n)) << "n = " << n;
    }
  };
  check(0.0, 1e-13);
  check(0.0f, 1e-13);  // (float entries, exact products and sums in double)
}

TEST(VectorOps, ReductionsAreBitwiseIndependentOfThreadCount) {
  const index n = 100003;
  const auto x = test::random_vector(n, 5), y = test::random_vector(n, 6);
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const real d1 = dot(n, x.data(), y.data());
  auto r1 = y;
  const real j1 = jacobi_cg_update(n, 0.37, x.data(), y.data(), r1.data());
  omp_set_num_threads(2);
  const real d2 = dot(n, x.data(), y.data());
  auto r2 = y;
  const real j2 = jacobi_cg_update(n, 0.37, x.data(), y.data(), r2.data());
  omp_set_num_threads(threads);
  EXPECT_EQ(d1, d2);
  EXPECT_EQ(j1, j2);
}

// The host's one partition (launch.hpp): every entry on one worker, shares
// within one entry of each other, and a worker's entries the same nodes in
// each of a vector's three components, whatever n and the worker count.
TEST(Partition, EntrySharesCoverEachEntryOnceAndKeepAWorkerOnItsNodes) {
  for (index n : {index(0), index(1), index(2), index(7), index(3 * 1000), index(3 * 4097), index(100003)})
    for (index w : {1, 2, 3, 5, 16, 128}) {
      std::vector<int> seen(std::size_t(n), 0);
      for (index c = 0; c < kThirds; ++c) {
        index smallest = n, largest = 0;
        for (index t = 0; t < w; ++t) {
          const Share s = entry_share(n, c, t, w);
          smallest = std::min(smallest, s.end - s.begin);
          largest = std::max(largest, s.end - s.begin);
          for (index i = s.begin; i < s.end; ++i) ++seen[std::size_t(i)];
          if (n % kThirds == 0) {  // a vector: the same nodes in every component
            const Share s0 = entry_share(n, 0, t, w);
            EXPECT_EQ(s.begin - s0.begin, c * (n / kThirds));
            EXPECT_EQ(s.end - s0.end, c * (n / kThirds));
          }
        }
        EXPECT_LE(largest - smallest, 1) << "n " << n << ", " << w << " workers";
      }
      for (index i = 0; i < n; ++i) ASSERT_EQ(seen[std::size_t(i)], 1) << "entry " << i << " of " << n << ", " << w << " workers";
    }
}

// ... and a worker's node rows (the apply, the transfers) are its nodes of
// every component up to one row at each end: on the mesh levels of the
// large runs, at the thread counts of servers
TEST(Partition, RowSharesAreTheNodesOfTheEntryShares) {
  for (int level : {8, 12, 14, 15}) {
    const auto d = level_dims(level);
    const index nx = d[0] + 1, rows = (d[1] + 1) * (d[2] + 1), N = nx * rows;
    for (index w : {2, 16, 64, 128})
      for (index t = 0; t < w; ++t) {
        const Share r = host_share(rows, t, w), e = entry_share(3 * N, 0, t, w);
        EXPECT_LT(std::abs(r.begin * nx - e.begin), nx) << "level " << level << ", worker " << t << " of " << w;
        EXPECT_LT(std::abs(r.end * nx - e.end), nx) << "level " << level << ", worker " << t << " of " << w;
      }
  }
}

// A launch's workers run on their own shares: what for_each_entry's body
// sees on worker t is t's entries, and sum_over_blocks adds every block
// once, each on the worker that owns its first entry.
TEST(Partition, LaunchesGiveEachThreadItsShare) {
  const index n = 3 * 50001;
  ASSERT_TRUE(worth_threads(double(n) * Cost{8, 0}));
  std::vector<int> owner(std::size_t(n), -1);
  int* o = owner.data();
  for_each_entry("owner", n, Cost{8, 0}, [=](index i) { o[i] = omp_get_thread_num(); });
  const index w = omp_get_max_threads();
  for (index t = 0; t < w; ++t)
    for (index c = 0; c < kThirds; ++c) {
      const Share s = entry_share(n, c, t, w);
      for (index i = s.begin; i < s.end; ++i) ASSERT_EQ(owner[std::size_t(i)], t) << "entry " << i;
    }
  const real blocks = sum_over_blocks(
      "owner sum", n, 1000, Cost{8, 0},
      [&](index i0, index i1) { return real(i1 - i0) * (o[i0] == omp_get_thread_num() ? 1 : -1); },
      [](index) { return real(1); });
  EXPECT_EQ(blocks, real(n));
}

// the fork/join census (launch.hpp): each launch counted once, as a parallel
// region where its work is worth threads, on the calling thread otherwise
TEST(VectorOps, LaunchesAreCountedByWhereTheyRan) {
  const index big = 1 << 20, small = 8;
  ASSERT_TRUE(worth_threads(double(big) * kAxpyCost));
  ASSERT_FALSE(worth_threads(double(small) * kAxpyCost));
  const auto x = test::random_vector(big, 11);
  auto y = test::random_vector(big, 12);
  const LaunchCounts a = launch_counts();
  axpy(big, 0.5, x.data(), y.data());
  const LaunchCounts b = launch_counts();
  axpy(small, 0.5, x.data(), y.data());
  axpy(small, 0.5, x.data(), y.data());
  const LaunchCounts c = launch_counts();
  EXPECT_EQ(b.threaded - a.threaded, 1);
  EXPECT_EQ(b.one_thread - a.one_thread, 0);
  EXPECT_EQ(c.threaded - b.threaded, 0);
  EXPECT_EQ(c.one_thread - b.one_thread, 2);
  EXPECT_EQ(c.device, a.device);
}

// ... and by kernel: each launch under its kernel's name and where it ran,
// with its modelled traffic; a float variant under its own name; the
// profile's census since its reset holds only the launches after it
TEST(VectorOps, LaunchesAreCountedByKernel) {
  const index big = 1 << 20, small = 8;
  const auto x = test::random_vector(big, 17);
  auto y = test::random_vector(big, 18);
  const std::vector<float> xf(x.begin(), x.end());
  const auto& find = test::launches_of;
  const std::vector<KernelLaunches> a = launches_by_kernel();
  const LaunchCounts ca = launch_counts();
  profile_reset();
  axpy(big, 0.5, x.data(), y.data());
  axpy(small, 0.5, x.data(), y.data());
  axpy(small, 0.5, x.data(), y.data());
  (void)dot(big, xf.data(), xf.data());
  const std::vector<KernelLaunches> b = launches_by_kernel();
  const LaunchCounts cb = launch_counts();
  const KernelLaunches t0 = find(a, "axpy", Ran::threaded), t1 = find(b, "axpy", Ran::threaded);
  const KernelLaunches o0 = find(a, "axpy", Ran::one_thread), o1 = find(b, "axpy", Ran::one_thread);
  EXPECT_EQ(t1.calls - t0.calls, 1);
  EXPECT_DOUBLE_EQ(t1.bytes - t0.bytes, double(big) * kAxpyCost.bytes);
  EXPECT_DOUBLE_EQ(t1.flops - t0.flops, double(big) * kAxpyCost.flops);
  EXPECT_EQ(o1.calls - o0.calls, 2);
  EXPECT_DOUBLE_EQ(o1.bytes - o0.bytes, 2.0 * small * kAxpyCost.bytes);
  const KernelLaunches f0 = find(a, "dot (float)", Ran::threaded), f1 = find(b, "dot (float)", Ran::threaded);
  EXPECT_EQ(f1.calls - f0.calls, 1);
  EXPECT_DOUBLE_EQ(f1.bytes - f0.bytes, double(big) * in_precision<float>(kDotCost).bytes);
  EXPECT_EQ(find(b, "dot", Ran::threaded).calls, find(a, "dot", Ran::threaded).calls);
  // the same launches, the same seconds, as the census by where they ran
  EXPECT_NEAR((t1.seconds - t0.seconds) + (f1.seconds - f0.seconds), cb.threaded_seconds - ca.threaded_seconds, 1e-9);
  EXPECT_NEAR(o1.seconds - o0.seconds, cb.one_thread_seconds - ca.one_thread_seconds, 1e-9);
  // since the reset: these three rows only, the longest first
  const std::vector<KernelLaunches> since = kernel_launches_since_reset();
  ASSERT_EQ(since.size(), 3u);
  EXPECT_EQ(find(since, "axpy", Ran::threaded).calls, 1);
  EXPECT_EQ(find(since, "axpy", Ran::one_thread).calls, 2);
  EXPECT_EQ(find(since, "dot (float)", Ran::threaded).calls, 1);
  for (std::size_t i = 1; i < since.size(); ++i) EXPECT_GE(since[i - 1].seconds, since[i].seconds);
  EXPECT_STREQ(to_string(Ran::one_thread), "1 thread");
}

// ... and timed: a threaded launch's wall time in threaded_seconds, in the
// size class of its modelled work; a one-thread launch's in one_thread_seconds
TEST(VectorOps, LaunchesAreTimedAndSortedBySize) {
  const double per_entry = kAxpyCost.bytes + kAxpyCost.flops;
  const index largest = index(3e7 / per_entry) + 1;
  const auto x = test::random_vector(largest, 13);
  auto y = test::random_vector(largest, 14);
  for (int k = 0; k < LaunchCounts::kSizes; ++k) {
    const index n = index(1.5 * kParallelWork * std::pow(10.0, k) / per_entry);  // inside class k
    const LaunchCounts a = launch_counts();
    const double t0 = wall_time();
    axpy(n, 0.5, x.data(), y.data());
    const double wall = wall_time() - t0;
    const LaunchCounts b = launch_counts();
    for (int j = 0; j < LaunchCounts::kSizes; ++j) {
      EXPECT_EQ(b.by_size[j] - a.by_size[j], j == k ? 1 : 0) << "launch of " << n << " entries, class " << j;
      if (j != k) {
        EXPECT_EQ(b.by_size_seconds[j], a.by_size_seconds[j]);
      }
    }
    EXPECT_DOUBLE_EQ(b.by_size_work[k] - a.by_size_work[k], double(n) * per_entry);
    const double dt = b.threaded_seconds - a.threaded_seconds;
    EXPECT_GT(dt, 0);
    EXPECT_LE(dt, wall + 1e-9);
    EXPECT_NEAR(b.by_size_seconds[k] - a.by_size_seconds[k], dt, 1e-9);
    EXPECT_EQ(b.one_thread_seconds, a.one_thread_seconds);
  }
  const LaunchCounts a = launch_counts();
  axpy(8, 0.5, x.data(), y.data());
  const LaunchCounts b = launch_counts();
  EXPECT_GT(b.one_thread_seconds, a.one_thread_seconds);
  EXPECT_EQ(b.threaded_seconds, a.threaded_seconds);
}

// the profile's rows say how much of their time ran in parallel regions:
// all of a timed launch, none of a timed serial loop
TEST(VectorOps, ProfileRowsSayWhatRanThreaded) {
  const index n = 1 << 21;
  const auto x = test::random_vector(n, 15);
  auto y = test::random_vector(n, 16);
  ASSERT_TRUE(worth_threads(double(n) * kAxpyCost));
  profile_reset();
  {
    const ScopedTimer t(Kernel::vector, double(n) * kAxpyCost);
    for (int r = 0; r < 5; ++r) axpy(n, 0.5, x.data(), y.data());
  }
  {
    const ScopedTimer t(Kernel::contact_maps);  // serial work only
    volatile real s = 0;
    for (index i = 0; i < n; ++i) s = s + y[std::size_t(i)];
  }
  const LaunchCounts since = launches_since_reset();
  EXPECT_EQ(since.threaded, 5);
  EXPECT_EQ(since.one_thread, 0);
  double total = 0;
  for (const ProfileRow& r : profile_rows(1.0)) {
    if (r.kernel == kernel_name(Kernel::vector)) {
      EXPECT_GT(r.parallel, 0.9);  // the rest: the timer's own start and end
      EXPECT_LE(r.parallel, 1.0);
      total += r.self_seconds;
    }
    if (r.kernel == kernel_name(Kernel::contact_maps)) {
      EXPECT_EQ(r.parallel, 0);
    }
  }
  EXPECT_GT(total, 0);
  EXPECT_LE(since.threaded_seconds, total);
  profile_reset();
  EXPECT_EQ(launches_since_reset().threaded, 0);
}

TEST(VectorOps, ChebyshevUpdatesFollowTheirFormulas) {
  const index n = 1001;
  const auto dinv = test::random_vector(n, 7), r = test::random_vector(n, 8), x = test::random_vector(n, 10);
  const auto prev = test::random_vector(n, 9);
  auto y = prev;
  cheb_update(n, 0.3, 0.7, dinv.data(), r.data(), x.data(), y.data());
  for (index i = 0; i < n; ++i) ASSERT_NEAR(y[i], x[i] + 0.3 * (x[i] - prev[i]) + 0.7 * dinv[i] * r[i], 1e-14);
  // from zero: x_1 = t dinv b
  std::vector<real> x1(n, std::nan(""));
  cheb_first(n, 0.5, dinv.data(), r.data(), x1.data());
  for (index i = 0; i < n; ++i) ASSERT_NEAR(x1[i], 0.5 * dinv[i] * r[i], 1e-15);
  // from a guess: cheb_update with s = 0, bit for bit, and the guess left where r was
  auto r1 = r, x2 = x;
  std::vector<real> y2 = prev;
  cheb_first_on_guess(n, 0.7, dinv.data(), r1.data(), x2.data());
  cheb_update(n, 0.0, 0.7, dinv.data(), r.data(), x.data(), y2.data());
  for (index i = 0; i < n; ++i) {
    ASSERT_EQ(x2[i], y2[i]);
    ASSERT_EQ(r1[i], x[i]);
  }
}

// STREAM's triad (the roofline's and scaling's bandwidth reference), on the
// awkward lengths
TEST(VectorOps, TriadFollowsItsFormula) {
  for (index n : kLengths) {
    const auto b = test::random_vector(n, 13), c = test::random_vector(n, 14);
    std::vector<real> a(n, std::nan(""));
    triad(n, b.data(), -1.75, c.data(), a.data());
    for (index i = 0; i < n; ++i) ASSERT_NEAR(a[i], b[i] - 1.75 * c[i], 1e-15) << "n = " << n << ", " << i;
  }
}

// the three component blocks' runs in one launch: the plain loops' values
// there, every other entry untouched (N, first, count awkward: runs that
// begin mid-block, a run to the block's end, an empty one)
TEST(VectorOps, ComponentRunsTouchTheirRunsOnly) {
  const index N = 1003;
  for (const ComponentRuns r : {ComponentRuns{N, 17, 500}, ComponentRuns{N, 0, N}, ComponentRuns{N, 1002, 1},
                                ComponentRuns{N, 5, 0}}) {
    const std::string what = "first " + std::to_string(r.first) + ", count " + std::to_string(r.count);
    const auto x = test::random_vector(3 * N, 11), y0 = test::random_vector(3 * N, 12);
    auto in_run = [&](index k) { return k % N >= r.first && k % N < r.first + r.count; };
    auto y = y0;
    axpy(r, 0.3, x.data(), y.data());
    for (index k = 0; k < 3 * N; ++k) ASSERT_EQ(y[k], in_run(k) ? y0[k] + 0.3 * x[k] : y0[k]) << what << ", " << k;
    y = y0;
    scale(r, -2.5, y.data());
    for (index k = 0; k < 3 * N; ++k) ASSERT_EQ(y[k], in_run(k) ? -2.5 * y0[k] : y0[k]) << what << ", " << k;
    y = y0;
    copy(r, x.data(), y.data());
    for (index k = 0; k < 3 * N; ++k) ASSERT_EQ(y[k], in_run(k) ? x[k] : y0[k]) << what << ", " << k;
    y = y0;
    fill(r, 7.0, y.data());
    for (index k = 0; k < 3 * N; ++k) ASSERT_EQ(y[k], in_run(k) ? 7.0 : y0[k]) << what << ", " << k;
  }
}

}  // namespace tresca
