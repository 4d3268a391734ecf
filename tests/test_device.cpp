// The device backend (kernels/launch.hpp, issue 22): the vector kernels,
// launched as OpenMP target regions over device memory, against the same
// kernels on the host. A TRESCA_OFFLOAD build runs these on its GPU, or
// with no GPU present on the host (which still compiles every body for
// nvptx and runs it through the target-region code path); a build
// without offload skips them and says so.
#include <gtest/gtest.h>
#include <omp.h>

#include <cstdlib>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "kernels/elasticity.hpp"
#include "kernels/launch.hpp"
#include "kernels/vector_ops.hpp"
#include "test_helpers.hpp"

namespace tresca {

namespace {
// a device copy of a host vector, freed at scope exit
struct DeviceVector {
  index n;
  real* p;
  explicit DeviceVector(const std::vector<real>& host)
      : n(index(host.size())), p(static_cast<real*>(device_allocate(host.size() * sizeof(real)))) {
    copy_to_device(p, host.data(), host.size() * sizeof(real));
  }
  ~DeviceVector() { device_free(p); }
  DeviceVector(const DeviceVector&) = delete;
  DeviceVector& operator=(const DeviceVector&) = delete;
  std::vector<real> host() const {
    std::vector<real> h(n);
    copy_from_device(h.data(), p, h.size() * sizeof(real));
    return h;
  }
};

// launches go to the device inside this scope
struct OnDevice {
  OnDevice() { set_launch_on_device(true); }
  ~OnDevice() { set_launch_on_device(false); }
};

const index kLengths[] = {1, 7, kDotBlock - 1, kDotBlock + 1, 5 * kDotBlock + 43, 100003};
}  // namespace

// where a GPU run is meant (perf/gpu_bundle.sh's run.sh sets it): fail,
// rather than pass on the host, when no device is there (GCC 12 runs the
// target regions on the host even with OMP_TARGET_OFFLOAD=MANDATORY)
TEST(Device, PresentWhereRequired) {
  if (!std::getenv("TRESCA_REQUIRE_DEVICE")) GTEST_SKIP() << "TRESCA_REQUIRE_DEVICE unset";
  EXPECT_GT(omp_get_num_devices(), 0) << "no offload device: " << device_description();
}

TEST(Device, WithoutOffloadTheDeviceIsRefused) {
  if (offload_built()) GTEST_SKIP() << "an offload build: " << device_description();
  EXPECT_THROW(set_launch_on_device(true), std::invalid_argument);
  EXPECT_FALSE(launch_on_device());
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
    DeviceVector dx(x), dy(y), dq(y), dr(r), dx2(x);
    real dd = 0, drr = 0;
    {
      OnDevice on;
      axpy(n, 0.5, dx.p, dy.p);
      xpay(n, dx.p, -0.25, dy.p);
      dd = dot(n, dx.p, dq.p);
      drr = cg_update(n, 0.37, dx.p, dq.p, dx2.p, dr.p);
    }
    EXPECT_LE(test::max_abs_diff(dy.host(), hy), 1e-15 * std::max(real(1), test::max_abs(hy))) << "axpy/xpay, n = " << n;
    EXPECT_NEAR(dd, hd, 1e-13 * std::max(real(1), std::abs(hd))) << "dot, n = " << n;
    EXPECT_NEAR(drr, hrr, 1e-13 * hrr) << "cg_update, n = " << n;
    EXPECT_LT(test::max_abs_diff(dx2.host(), hx), 1e-15) << "cg_update x, n = " << n;
    EXPECT_LT(test::max_abs_diff(dr.host(), hr), 1e-15) << "cg_update r, n = " << n;
  }
}

// the stencil apply in its row form, stencil and vectors in device memory,
// against the banded apply on the host, plain and fused, double and float
TEST(Device, StencilApplyOnTheDeviceMatchesTheHost) {
  if (!offload_built()) GTEST_SKIP() << "built without TRESCA_OFFLOAD: no device backend to test";
  for (unsigned faces : {0u, unsigned(kFaceX0 | kFaceZ0)}) {
    const GridDims g = test::prism(21, 6, 5);
    const ElasticityStencil k = build_elasticity_stencil(g, faces, 1.0, 0.3);
    const auto x = test::random_vector(k.size(), 8), b = test::random_vector(k.size(), 9);
    const RowBlock all{0, g.nz(), 0, g.ny()};
    std::vector<real> hy(k.size()), hr(k.size());
    elasticity_apply(k, x.data(), hy.data(), all);
    elasticity_apply(k, x.data(), hr.data(), all, b.data());
    const DeviceStencil<real> dk(k);
    DeviceVector dx(x), db(b), dy(std::vector<real>(k.size(), 7.0)), dr(std::vector<real>(k.size(), 7.0));
    {
      OnDevice on;
      elasticity_apply_rows(dk.view(), dx.p, dy.p, all);
      elasticity_apply_rows(dk.view(), dx.p, dr.p, all, db.p);
    }
    EXPECT_LE(test::max_abs_diff(dy.host(), hy), 1e-14 * test::max_abs(hy)) << "faces " << faces;
    EXPECT_LE(test::max_abs_diff(dr.host(), hr), 1e-14 * test::max_abs(hr)) << "faces " << faces;
  }
}

}  // namespace tresca
