// The device backend (kernels/launch.hpp, issue 22): the vector kernels,
// launched as OpenMP target regions over device memory, against the same
// kernels on the host. A TRESCA_OFFLOAD build runs these on its GPU, or
// with no GPU present on the host (which still compiles every body for
// nvptx and runs it through the target-region code path); a build
// without offload skips them and says so.
#include <gtest/gtest.h>
#include <omp.h>

#include <cstdint>
#include <cstdlib>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/contact/run.hpp"
#include "core/fem/problem.hpp"
#include "core/multigrid/interior.hpp"
#include "core/multigrid/multigrid.hpp"
#include "core/util/profile.hpp"
#include "kernels/elasticity.hpp"
#include "kernels/transfer.hpp"
#include "kernels/launch.hpp"
#include "kernels/vector_ops.hpp"
#include "test_helpers.hpp"

namespace tresca {

namespace {
// host values in a Field on the device (kernels/field.hpp)
template <class T = real>
Field<T> on_device(const std::vector<real>& host) {
  Field<T> f(host.begin(), host.end());
  f.move_to(Space::device);
  return f;
}

// launches (and the Fields they make) go to the device inside this scope
struct OnDevice {
  OnDevice() { set_launch_on_device(true); }
  ~OnDevice() { set_launch_on_device(false); }
};

const index kLengths[] = {1, 7, kDotBlock - 1, kDotBlock + 1, 5 * kDotBlock + 43, 100003};
}  // namespace

// where a GPU run is meant (TRESCA_REQUIRE_DEVICE set, and not to 0:
// perf/gpu_run.sh sets it): fail, rather than pass on the host, when no
// device is there (GCC 12 runs the target regions on the host even with
// OMP_TARGET_OFFLOAD=MANDATORY)
TEST(Device, PresentWhereRequired) {
  const char* required = std::getenv("TRESCA_REQUIRE_DEVICE");
  if (!required || !*required || std::string(required) == "0")
    GTEST_SKIP() << "TRESCA_REQUIRE_DEVICE unset, empty or 0";
  EXPECT_GT(omp_get_num_devices(), 0) << "no offload device: " << device_description();
}

// the GPU a device run names (the run's header, JSON and bench_kernels'
// context) and whose memory its memory check holds it to: the CUDA
// driver's answer where a GPU is present, nothing elsewhere
TEST(Device, NamesTheGpuAndItsMemory) {
  const DeviceInfo d = device_info();
  if (omp_get_num_devices() == 0) {
    EXPECT_TRUE(d.name.empty());
    EXPECT_EQ(d.memory_bytes, 0);
    EXPECT_EQ(device_description().find("OpenMP offload"), std::string::npos) << device_description();
    GTEST_SKIP() << "no GPU: nothing to name (" << device_description() << ")";
  }
  EXPECT_FALSE(d.name.empty());
  EXPECT_GT(d.memory_bytes, 1e9);
  EXPECT_NE(device_description().find(": " + d.name + ", "), std::string::npos) << device_description();
}

TEST(Device, WithoutOffloadTheDeviceIsRefused) {
  if (offload_built()) GTEST_SKIP() << "an offload build: " << device_description();
  EXPECT_THROW(set_launch_on_device(true), std::invalid_argument);
  EXPECT_FALSE(launch_on_device());
}

// where a Field lives, in any build (without offload, "device" memory is
// the host's, through the same calls)
TEST(Field, LivesWhereItIsMadeAndMovesOnRequest) {
  Field<real> h{1, 2, 3};
  EXPECT_EQ(h.space(), Space::host);
  EXPECT_EQ(Field<real>(4).space(), launch_space());
  Field<real> d = h;
  d.move_to(Space::device);
  EXPECT_TRUE(d.on_device());
  EXPECT_THROW(d[0], std::logic_error) << "a device Field read on the host";
  EXPECT_THROW(d.begin(), std::logic_error);
  EXPECT_THROW(d.push_back(4), std::logic_error);
  d.resize(5);  // kept entries and zero new ones, on the device
  EXPECT_TRUE(d.on_device());
  EXPECT_EQ(d.to_vector(), (std::vector<real>{1, 2, 3, 0, 0}));
  const Field<real> c = d;  // a copy lives where its source does
  EXPECT_TRUE(c.on_device());
  EXPECT_EQ(c.to_vector(), d.to_vector());
  d.move_to(Space::host);
  EXPECT_EQ(d.space(), Space::host);
  EXPECT_EQ(d[4], 0);
  EXPECT_EQ(d[2], 3);
  Field<real> e;  // an empty Field has no place until it gets storage
  e.push_back(7);
  EXPECT_EQ(e.space(), Space::host);
  EXPECT_EQ(e.size(), 1u);
}

// A large block a Field gives back is handed to the next Field of its size
// (no page faults again), zeroed like a fresh one; the memory kept for that
// never lifts what is held above the most the live Fields ever needed
// plus a slack (the largest block or a 16th of that peak).
TEST(Field, AFreedLargeBlockIsReusedAndZeroed) {
  const std::size_t n = (std::size_t(3) << 20) / sizeof(real);  // 3 MiB: a kept size
  const real* first;
  {
    Field<real> a(n);
    std::fill(a.begin(), a.end(), 1.5);
    first = a.data();
  }
  const BlockReuse before = block_reuse(Space::host);
  Field<real> b(n);
  const BlockReuse after = block_reuse(Space::host);
  EXPECT_EQ(b.data(), first) << "the block just freed, handed out again";
  EXPECT_EQ(after.requests, before.requests + 1);
  EXPECT_EQ(after.reused, before.reused + 1);
  EXPECT_DOUBLE_EQ(after.reused_bytes - before.reused_bytes, double(n * sizeof(real)));
  EXPECT_TRUE(std::all_of(b.begin(), b.end(), [](real v) { return v == 0; })) << "a reused block is zeroed";
  // sizes that do not match: kept blocks are given back rather than held
  // above that bound
  for (std::size_t k = 1; k <= 6; ++k) {
    Field<real> c(n + k * 100000), d(n / 2 + k);
    const BlockReuse s = block_reuse(Space::host);
    EXPECT_LE(s.live_bytes + s.kept_bytes, s.held_limit_bytes) << "step " << k;
    EXPECT_GE(s.live_bytes, double((2 * n + n / 2 + k * 100000 + k) * sizeof(real)));
  }
}

// Temporaries of two sizes made and dropped in turn at the live peak (a
// Newton step's, every step): after the first of each, every one is a
// kept block. With the live peak alone as the bound each evicted the other
// and every one was made afresh.
TEST(Field, TemporariesOfTwoSizesInTurnAreReused) {
  const std::size_t n = (std::size_t(3) << 20) / sizeof(real);
  const BlockReuse s0 = block_reuse(Space::host);
  // lifts the live peak to this Field plus what is live now
  Field<real> held(std::size_t(s0.peak_bytes - s0.live_bytes) / sizeof(real) + n);
  const auto in_turn = [&] {
    { Field<real> a(n / 2 + 1); }
    { Field<real> b(n / 3 + 7); }
  };
  in_turn();
  const BlockReuse before = block_reuse(Space::host);
  for (int round = 0; round < 3; ++round) in_turn();
  const BlockReuse after = block_reuse(Space::host);
  EXPECT_EQ(after.requests - before.requests, 6);
  EXPECT_EQ(after.reused - before.reused, 6) << "each temporary a kept block";
  EXPECT_LE(after.live_bytes + after.kept_bytes, after.held_limit_bytes);
}

// A copy assigned to a Field of its size and space lands in that Field's
// own storage (no block made and dropped: a Newton step's masks); of
// another size, in new storage. The entries are the source's either way.
TEST(Field, CopyAssignmentReusesStorageOfTheSameSize) {
  Field<real> a(1000, 2.5), b(1000, -1.0), c(10, 7.0);
  const real* own = b.data();
  b = a;
  EXPECT_EQ(b.data(), own);
  EXPECT_NE(b.data(), a.data());
  EXPECT_EQ(b.to_vector(), a.to_vector());
  c = a;
  EXPECT_EQ(c.size(), a.size());
  EXPECT_EQ(c.to_vector(), a.to_vector());
  a[3] = 9;  // the copies are copies
  EXPECT_EQ(b[3], 2.5);
  EXPECT_EQ(c[3], 2.5);
  Field<real> e;
  e = a;
  EXPECT_EQ(e.to_vector(), a.to_vector());
}

// copies and zeroing of large host ranges are split among the threads (each
// its share of the bytes, first touch in parallel): every byte, at any
// length and thread count
TEST(Field, LargeCopiesAndZeroingCoverEveryByte) {
  const int keep = omp_get_max_threads();
  for (const std::size_t n : {std::size_t(1000003), std::size_t(3) << 20}) {
    std::vector<std::uint8_t> v(n);
    for (std::size_t i = 0; i < n; ++i) v[i] = std::uint8_t(1 + i % 251);
    for (int threads : {1, 2, 3, 7}) {
      omp_set_num_threads(threads);
      Field<std::uint8_t> a(v.begin(), v.end());
      const Field<std::uint8_t> b = a;  // host to host: a copy by shares
      EXPECT_TRUE(std::equal(b.begin(), b.end(), v.begin())) << n << " bytes, " << threads << " threads";
      a.clear();
      a.resize(n);  // kept storage, new entries zero: zeroing by shares
      EXPECT_TRUE(std::all_of(a.begin(), a.end(), [](std::uint8_t x) { return x == 0; }))
          << n << " bytes, " << threads << " threads";
    }
  }
  omp_set_num_threads(keep);
}

// why a DeviceGuard test cannot run here ("": it can): the guard is off, a
// GPU guards its own memory, or (where it needs device launches) the build
// has no offload
static std::string why_no_guard(bool needs_launches) {
  const char* e = std::getenv("TRESCA_DEVICE_GUARD");
  if (!e || std::string(e) != "1") return "TRESCA_DEVICE_GUARD unset";
  if (omp_get_num_devices() > 0) return "a GPU is present: its memory guards itself";
  if (needs_launches && !offload_built()) return "built without TRESCA_OFFLOAD: no device launches";
  return "";
}

// the guard that the device.guarded run relies on: a host read through a
// device pointer stops the program
TEST(DeviceGuard, StopsAHostReadOfDeviceMemory) {
  const std::string why = why_no_guard(false);
  if (!why.empty()) GTEST_SKIP() << why;
  ASSERT_TRUE(device_guarded());
  const Field<real> d = on_device({1, 2, 3});
  EXPECT_EQ(d.to_vector()[1], 2);  // through a copy: allowed
  EXPECT_DEATH(
      {
        volatile real v = d.data()[1];
        (void)v;
      },
      "");
}

// ... and a kernel that reads host memory (an illegal address on a GPU)
// stops it too, while the same kernel over device memory runs
TEST(DeviceGuard, StopsAKernelReadOfHostMemory) {
  const std::string why = why_no_guard(true);
  if (!why.empty()) GTEST_SKIP() << why;
  const Field<real> host{1, 2, 3};
  OnDevice on;
  const Field<real> x = on_device({1, 2, 3});
  Field<real> y(3);
  copy(3, x.data(), y.data());
  EXPECT_EQ(y.to_vector()[2], 3);
  EXPECT_DEATH(copy(3, host.data(), y.data()), "");
}

// ... and so does a kernel given a host array that is not a Field (a
// std::vector's data: the guard cannot close malloc's heap, so it reads
// the launch's body for an address there; found on an H200, where the
// Coulomb fixed point's Anderson sums ran the device's dot over its host
// vectors, RESULTS.md §0zm)
TEST(DeviceGuard, StopsAKernelGivenAHostArray) {
  const std::string why = why_no_guard(true);
  if (!why.empty()) GTEST_SKIP() << why;
  const std::vector<real> host{1, 2, 3};
  OnDevice on;
  const Field<real> x = on_device({1, 2, 3});
  EXPECT_EQ(dot(3, x.data(), x.data()), 14);
  EXPECT_THROW(dot(3, host.data(), x.data()), std::logic_error);
  EXPECT_THROW(dot(3, x.data(), host.data()), std::logic_error);
  {
    const HostLaunches on_the_host;  // (where host arrays belong)
    EXPECT_EQ(dot(3, host.data(), host.data()), 14);
  }
}

TEST(Device, VectorKernelsOnTheDeviceMatchTheHost) {
  if (!offload_built()) GTEST_SKIP() << "built without TRESCA_OFFLOAD: no device backend to test";
  std::printf("device: %s\n", device_description().c_str());
  for (index n : kLengths) {
    const auto x = test::random_vector(n, 1), y = test::random_vector(n, 2), r = test::random_vector(n, 3);
    // the host's answers
    auto hy = y, hr = r, hx = x;
    axpy(n, 0.5, x.data(), hy.data());
    xpay(n, x.data(), -0.25, hy.data());
    const real hd = dot(n, x.data(), y.data());
    const real hrr = cg_update(n, 0.37, x.data(), y.data(), hx.data(), hr.data());
    // the device's
    Field<real> dx = on_device(x), dy = on_device(y), dq = on_device(y), dr = on_device(r), dx2 = on_device(x);
    real dd = 0, drr = 0;
    {
      OnDevice on;
      axpy(n, 0.5, dx.data(), dy.data());
      xpay(n, dx.data(), -0.25, dy.data());
      dd = dot(n, dx.data(), dq.data());
      drr = cg_update(n, 0.37, dx.data(), dq.data(), dx2.data(), dr.data());
    }
    EXPECT_LE(test::max_abs_diff(dy.to_vector(), hy), 1e-15 * std::max(real(1), test::max_abs(hy)))
        << "axpy/xpay, n = " << n;
    EXPECT_NEAR(dd, hd, 1e-13 * std::max(real(1), std::abs(hd))) << "dot, n = " << n;
    EXPECT_NEAR(drr, hrr, 1e-13 * hrr) << "cg_update, n = " << n;
    EXPECT_LT(test::max_abs_diff(dx2.to_vector(), hx), 1e-15) << "cg_update x, n = " << n;
    EXPECT_LT(test::max_abs_diff(dr.to_vector(), hr), 1e-15) << "cg_update r, n = " << n;
  }
  // the three component blocks' runs in one launch (a plane of a 3D vector)
  const index N = 1003;
  const ComponentRuns runs{N, 17, 500};
  const auto x = test::random_vector(3 * N, 4), y = test::random_vector(3 * N, 5);
  auto hy = y, hz = y;
  scale(runs, -1, hy.data());
  axpy(runs, 0.5, x.data(), hy.data());
  copy(runs, x.data(), hz.data());
  fill(ComponentRuns{N, 600, 3}, 2.0, hz.data());
  Field<real> dx = on_device(x), dy = on_device(y), dz = on_device(y);
  {
    OnDevice on;
    scale(runs, -1, dy.data());
    axpy(runs, 0.5, dx.data(), dy.data());
    copy(runs, dx.data(), dz.data());
    fill(ComponentRuns{N, 600, 3}, 2.0, dz.data());
  }
  EXPECT_EQ(dy.to_vector(), hy) << "scale, axpy on component runs";
  EXPECT_EQ(dz.to_vector(), hz) << "copy, fill on component runs";
}

// device launches are counted and timed as such (the profile's "on the
// device" line), none of them as a host launch
TEST(Device, LaunchesOnTheDeviceAreCountedAndTimed) {
  if (!offload_built()) GTEST_SKIP() << "built without TRESCA_OFFLOAD: no device backend to test";
  const index n = 1 << 20;
  Field<real> x = on_device(test::random_vector(n, 4)), y = on_device(test::random_vector(n, 5));
  LaunchCounts a, b;
  double wall = 0;
  {
    OnDevice on;
    a = launch_counts();
    const double t0 = omp_get_wtime();
    axpy(n, 0.5, x.data(), y.data());
    (void)dot(n, x.data(), y.data());
    wall = omp_get_wtime() - t0;
    b = launch_counts();
  }
  EXPECT_EQ(b.device - a.device, 2);
  EXPECT_GT(b.device_seconds, a.device_seconds);
  EXPECT_LE(b.device_seconds - a.device_seconds, wall + 1e-9);
  EXPECT_EQ(b.threaded, a.threaded);
  EXPECT_EQ(b.one_thread, a.one_thread);
  EXPECT_EQ(b.threaded_seconds, a.threaded_seconds);
  // and by kernel: each launch under its name, as a target region; a field
  // moved to the device and back under the copies, with its bytes
  profile_reset();
  {
    OnDevice on;
    axpy(n, 0.5, x.data(), y.data());
    (void)dot(n, x.data(), y.data());
  }
  Field<real> z = on_device(test::random_vector(n, 6));
  z.move_to(Space::host);
  const std::vector<KernelLaunches> since = kernel_launches_since_reset();
  auto find = [&](const std::string& kernel, Ran ran) { return test::launches_of(since, kernel, ran); };
  EXPECT_EQ(find("axpy", Ran::device).calls, 1);
  EXPECT_DOUBLE_EQ(find("axpy", Ran::device).bytes, double(n) * kAxpyCost.bytes);
  EXPECT_EQ(find("dot", Ran::device).calls, 1);
  EXPECT_EQ(find("axpy", Ran::threaded).calls + find("axpy", Ran::one_thread).calls, 0);
  EXPECT_EQ(find("copy host to device", Ran::copy).calls, 1);
  EXPECT_DOUBLE_EQ(find("copy host to device", Ran::copy).bytes, double(n) * sizeof(real));
  EXPECT_EQ(find("copy device to host", Ran::copy).calls, 1);
}

// the stencil apply (its row form on the device), stencil and vectors made
// with the launches on the device, against the banded apply on the host,
// plain, residual and a Chebyshev step, double and float; on rows shorter
// and longer than the 128 nodes from which a lane sweeps 4 nodes at once
// (kernels/elasticity.cpp; 149 interior nodes: the last lanes' 4th node past
// the run's end)
TEST(Device, StencilApplyOnTheDeviceMatchesTheHost) {
  if (!offload_built()) GTEST_SKIP() << "built without TRESCA_OFFLOAD: no device backend to test";
  for (const GridDims& g : {test::prism(21, 6, 5), test::prism(150, 3, 2)}) {
    for (unsigned faces : {0u, unsigned(kFaceX0 | kFaceZ0)}) {
      const ElasticityStencil k = build_elasticity_stencil(g, faces, 1.0, 0.3);
      const auto x = test::random_vector(k.size(), 8), b = test::random_vector(k.size(), 9);
      std::vector<real> diag(k.size());
      elasticity_diagonal_ref(k, diag.data());
      const auto dinv = test::step_weights(g, faces, diag, 10), p0 = test::random_vector(k.size(), 11);
      const RowBlock all{0, g.nz(), 0, g.ny()};
      std::vector<real> hy(k.size()), hr(k.size()), hs = p0;  // (the step's y: the iterate before x)
      elasticity_apply(k, x.data(), hy.data(), all);
      elasticity_apply(k, x.data(), hr.data(), all, b.data());
      elasticity_apply(k, x.data(), chebyshev_out(b.data(), dinv.data(), 0.5, 0.25, hs.data()), all);
      const ElasticityStencilT<float> kf = stencil_in_precision<float>(k);
      std::vector<float> xf(x.begin(), x.end()), hyf(k.size());
      elasticity_apply(kf, xf.data(), hyf.data(), all);
      Field<real> dy, dr, ds;
      Field<float> dyf;
      {
        OnDevice on;
        const ElasticityStencil dk = build_elasticity_stencil(g, faces, 1.0, 0.3);
        const ElasticityStencilT<float> dkf = stencil_in_precision<float>(dk);
        ASSERT_TRUE(dk.groups.on_device() && dkf.groups.on_device());
        Field<real> dx = on_device(x), db = on_device(b), ddinv = on_device(dinv);
        Field<float> dxf = on_device<float>(x);
        ds = on_device(p0);
        dy.resize(k.size());
        dr.resize(k.size());
        dyf.resize(k.size());
        elasticity_apply(dk, dx.data(), dy.data(), all);
        elasticity_apply(dk, dx.data(), dr.data(), all, db.data());
        elasticity_apply(dk, dx.data(), chebyshev_out(db.data(), ddinv.data(), 0.5, 0.25, ds.data()), all);
        elasticity_apply(dkf, dxf.data(), dyf.data(), all);
      }
      const std::string what = "nx " + std::to_string(g.nx()) + ", faces " + std::to_string(faces);
      EXPECT_LE(test::max_abs_diff(dy.to_vector(), hy), 1e-14 * test::max_abs(hy)) << what;
      EXPECT_LE(test::max_abs_diff(dr.to_vector(), hr), 1e-14 * test::max_abs(hr)) << what;
      EXPECT_LE(test::max_abs_diff(ds.to_vector(), hs), 1e-14 * test::max_abs(hs)) << what;
      const std::vector<float> yf = dyf.to_vector();
      EXPECT_LE(test::max_abs_diff(std::vector<real>(yf.begin(), yf.end()), std::vector<real>(hyf.begin(), hyf.end())),
                1e-5 * test::max_abs(hy))
          << "float, " << what;
    }
  }
}

// restriction and prolongation onto a base on the device (out of place)
// against the host (in place)
TEST(Device, TransfersOnTheDeviceMatchTheHost) {
  if (!offload_built()) GTEST_SKIP() << "built without TRESCA_OFFLOAD: no device backend to test";
  const GridDims f = test::prism(13, 7, 9), c = test::prism(7, 4, 5);
  const Transfer t = build_transfer(f, c);
  const auto xf = test::random_vector(3 * f.nodes(), 4), xc = test::random_vector(3 * c.nodes(), 5);
  std::vector<real> hc(3 * c.nodes()), hf = xf;
  restrict_to_coarse(t, 3, xf.data(), hc.data());
  prolongate(t, 3, xc.data(), hf.data(), hf.data());
  Field<real> dc, df;
  {
    OnDevice on;
    const Transfer dt = build_transfer(f, c);
    ASSERT_TRUE(dt.axis[0].j0.on_device());
    const Field<real> dxf = on_device(xf), dxc = on_device(xc);
    dc.resize(3 * c.nodes());
    df.resize(3 * f.nodes());
    restrict_to_coarse(dt, 3, dxf.data(), dc.data());
    prolongate(dt, 3, dxc.data(), df.data(), dxf.data());
  }
  EXPECT_LE(test::max_abs_diff(dc.to_vector(), hc), 1e-14 * test::max_abs(hc));
  EXPECT_LE(test::max_abs_diff(df.to_vector(), hf), 1e-14 * test::max_abs(hf));
}

// a whole MG-preconditioned CG solve with every operator, level and Krylov
// vector made on the device, the coarse levels on the host from none to
// all but the finest (GridHierarchy's device_min_nodes; the guard checks
// that each side reads only its own memory): the host's iterations and
// solution
TEST(Device, MultigridSolveOnTheDeviceMatchesTheHost) {
  if (!offload_built()) GTEST_SKIP() << "built without TRESCA_OFFLOAD: no device backend to test";
  for (Precision prec : {Precision::double_precision, Precision::single_precision})
    for (bool odd : {false, true}) {
      const Problem P = odd ? make_problem(spec_for_dims(23, 11, 13)) : make_problem(spec_for_level(5));
      MGOptions mo;
      mo.precision = prec;
      mo.coarse_nodes = 60;
      const Rediscretisation op = elasticity_on(P.interior_faces, P.spec.E, P.spec.nu);
      const Multigrid hmg(GridHierarchy::build(P.grid, mo.coarse_nodes, Comm::self(), kMinNodesPerRank, 200), op, mo);
      ASSERT_EQ(hmg.num_levels(), 4);  // 4032-4056, 637, 112, 36 nodes
      for (int l = 0; l < 4; ++l) EXPECT_FALSE(hmg.hierarchy()->levels[l].on_host) << "a host run has no host levels";
      const InteriorSolution h = solve_interior_elasticity(P, hmg, 1e-10);
      // device_min_nodes -> the first level on the host (4: none)
      for (const auto& [min_nodes, first_host] : {std::pair<index, int>{0, 4}, {200, 2}, {index(1) << 40, 1}}) {
        const std::string what = std::string(to_string(prec)) + (odd ? ", 23x11x13" : ", level 5") +
                                 ", device_min_nodes " + std::to_string(min_nodes);
        InteriorSolution d;
        {
          OnDevice on;
          const Multigrid dmg(GridHierarchy::build(P.grid, mo.coarse_nodes, Comm::self(), kMinNodesPerRank, min_nodes),
                              op, mo);
          ASSERT_EQ(dmg.num_levels(), hmg.num_levels()) << what;
          for (int l = 0; l < dmg.num_levels(); ++l) {
            EXPECT_EQ(dmg.hierarchy()->levels[l].on_host, l >= first_host) << what << ", level " << l;
            EXPECT_EQ(dmg.op(l).stencil().groups.on_device(), l < first_host) << what << ", level " << l;
          }
          EXPECT_EQ(dmg.describe().find("(h)") != std::string::npos, first_host < 4) << what;
          d = solve_interior_elasticity(P, dmg, 1e-10);
          EXPECT_TRUE(d.u.on_device()) << what;
        }
        ASSERT_TRUE(h.stats.ok() && d.stats.ok()) << what;
        EXPECT_EQ(d.stats.iterations, h.stats.iterations) << what;
        EXPECT_NEAR(d.relative_residual, h.relative_residual, 0.1 * h.relative_residual) << what;
        const std::vector<real> hu = h.u.to_vector();
        EXPECT_LE(test::max_abs_diff(d.u.to_vector(), hu), 1e-10 * test::max_abs(hu)) << what;
      }
    }
}

// a multigrid made with the launches on the host, applied with them on the
// device: refused with the reason, not read through host pointers
TEST(Device, HostMadeMultigridIsRefusedOnTheDevice) {
  if (!offload_built()) GTEST_SKIP() << "built without TRESCA_OFFLOAD: no device backend to test";
  const Problem P = make_problem(spec_for_level(2));
  const Multigrid mg(P.grid, P.interior_faces, P.spec.E, P.spec.nu);
  Field<real> r(P.dofs()), z(P.dofs());
  OnDevice on;
  EXPECT_THROW(mg.apply(r.data(), z.data()), std::logic_error);
}

// a multigrid on a hierarchy built with the launches elsewhere (whose
// finest transfers live there): refused when it is made, either way
TEST(Device, MultigridOnAHierarchyOfTheOtherSideIsRefused) {
  if (!offload_built()) GTEST_SKIP() << "built without TRESCA_OFFLOAD: no device backend to test";
  const Problem P = make_problem(spec_for_level(3));
  const Rediscretisation op = elasticity_on(P.interior_faces, P.spec.E, P.spec.nu);
  const auto on_host = GridHierarchy::build(P.grid, 60);
  std::shared_ptr<const GridHierarchy> on_device;
  {
    OnDevice on;
    on_device = GridHierarchy::build(P.grid, 60);
    EXPECT_THROW(Multigrid(on_host, op), std::logic_error);
  }
  EXPECT_THROW(Multigrid(on_device, op), std::logic_error);
}

// the whole contact solve (nested iteration, Newton, the final check) with
// every operator, level, Krylov and contact vector made on the device: the
// host's Newton and Krylov iterations, contact values to 1e-10 relative
// (issue 22's bar), for Tresca and for Coulomb by Newton and by the fixed point
TEST(Device, ContactSolveOnTheDeviceMatchesTheHost) {
  if (!offload_built()) GTEST_SKIP() << "built without TRESCA_OFFLOAD: no device backend to test";
  using Method = FrictionLaw::CoulombMethod;
  struct Case {
    const char* what;
    FrictionLaw friction;
    bool recover;
  };
  const Case cases[] = {{"Tresca", FrictionLaw{}, true},
                        {"Coulomb 0.8 (newton)", coulomb_friction(0.8, Method::newton), false},
                        {"Coulomb 0.8 (fixed point)", coulomb_friction(0.8, Method::fixed_point), false}};
  for (const Case& c : cases) {
    RunOptions o;
    o.friction = c.friction;
    o.recover_interior = c.recover;
    o.nested_min_contact_nodes = 40;
    const ProblemSpec spec = spec_for_level(4);
    const RunResult h = run_tresca(spec, o);
    RunResult d;
    {
      OnDevice on;
      d = run_tresca(spec, o);
    }
    ASSERT_TRUE(h.converged() && d.converged()) << c.what << ": " << h.reason() << " / " << d.reason();
    EXPECT_EQ(d.newton_steps(), h.newton_steps()) << c.what;
    EXPECT_EQ(d.newton.outer_iterations, h.newton.outer_iterations) << c.what;
    EXPECT_EQ(d.inner_iterations, h.inner_iterations) << c.what;
    ASSERT_EQ(d.nested.size(), h.nested.size()) << c.what;
    // the coarser meshes under device_min_nodes() were solved on the host
    // (TRESCA_DEVICE_MIN_NODES: ctest runs this both ways)
    for (std::size_t k = 0; k < d.nested.size(); ++k) {
      EXPECT_EQ(d.nested[k].on_device, d.nested[k].spec.nodes() >= device_min_nodes()) << c.what << ", mesh " << k;
      EXPECT_FALSE(h.nested[k].on_device) << c.what << ", mesh " << k;
    }
    EXPECT_LE(test::max_abs_diff(d.newton.u, h.newton.u), 1e-10 * test::max_abs(h.newton.u)) << c.what;
    EXPECT_LE(test::max_abs_diff(d.newton.lambda, h.newton.lambda), 1e-10 * test::max_abs(h.newton.lambda)) << c.what;
    EXPECT_LE(test::max_abs_diff(d.report.r, h.report.r), 1e-10 * test::max_abs(h.report.r)) << c.what;
    EXPECT_EQ(d.report.status, h.report.status) << c.what;
    // the results are host values
    EXPECT_FALSE(d.u_full.on_device()) << c.what;
    // what the device's Fields held at most is reported (at least the fine
    // mesh's 3D vectors of the V-cycle and the inner CG), a CPU run's is 0
    EXPECT_GE(d.peak_device_memory, 4.0 * 3 * double(spec.nodes()) * sizeof(real)) << c.what;
    EXPECT_EQ(h.peak_device_memory, 0.0) << c.what;
    if (c.recover) {
      const std::vector<real> hu = h.u_full.to_vector();
      EXPECT_LE(test::max_abs_diff(d.u_full.to_vector(), hu), 1e-10 * test::max_abs(hu)) << c.what;
    }
  }
}

}  // namespace tresca
