// Cliff guard: the optimised elasticity apply must stay far faster than its
// textbook _ref twin on whatever target this binary was compiled for, in
// each instruction-set variant it holds (kernels/isa.hpp).
//
// A ratio measured in one process on one thread, not an absolute time, so it
// holds on any machine: both kernels see the same CPU, clock and load. The
// optimised kernel is 10-30x faster than _ref when its vectors match the
// target's registers (perf/RESULTS.md); when they do not (e.g. 512-bit vectors
// compiled for AVX2, -DTRESCA_SIMD_BYTES=64 -march=x86-64-v3) every vector
// operation is split and goes through memory and the ratio drops to about 1.
// The floor of 5 is generous on purpose: it is a cliff detector, not a
// benchmark (those live in perf/).
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>

#include "core/fem/problem.hpp"
#include "core/util/profile.hpp"
#include "kernels/elasticity.hpp"
#include "kernels/isa.hpp"
#include "test_helpers.hpp"

namespace tresca {

TEST(KernelSpeed, OptimisedApplyIsFarFasterThanItsReferenceTwin) {
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const Problem P = make_problem(spec_for_level(7));  // 46x23x23 bricks, 81k dofs
  const ElasticityStencil k = build_elasticity_stencil(P.grid, P.interior_faces, P.spec.E, P.spec.nu);
  const auto x = test::random_vector(k.size(), 11);
  std::vector<real> y(k.size()), yr(k.size());
  const index nz = P.grid.nz();
  test::for_each_isa([&](const IsaKernels&) {
    // interleave the two kernels so a transient slowdown hits both
    double t_opt = 1e300, t_ref = 1e300;
    for (int round = 0; round < 3; ++round) {
      t_ref = std::min(t_ref, best_time(2, [&] { elasticity_apply_ref(k, x.data(), yr.data(), 0, nz); }));
      t_opt = std::min(t_opt, best_time(10, [&] { elasticity_apply(k, x.data(), y.data(), 0, nz); }));
    }
    const double ratio = t_ref / t_opt;
    std::printf("[ %s ] apply %.1f M dof/s, _ref %.1f M dof/s, ratio %.1f (1 thread, level 7)\n",
                build_info().c_str(), double(k.size()) / t_opt * 1e-6, double(k.size()) / t_ref * 1e-6, ratio);
    EXPECT_GT(ratio, 5.0) << "the optimised apply lost its vectorisation on " << build_info();
    EXPECT_LT(test::max_abs_diff(y, yr), 1e-12 * test::max_abs(yr));  // and it computes the same thing
  });
  omp_set_num_threads(threads);
}

// Without TRESCA_ISA the widest variant this processor runs is in use, and
// on a processor with AVX-512 that is the x86-64-v4 variant's 64-byte vectors
// (kernels/isa.hpp); the baseline is always there, last.
TEST(KernelSpeed, TheWidestVariantTheProcessorRunsIsChosen) {
  const char* forced = std::getenv("TRESCA_ISA");
  if (forced && *forced) GTEST_SKIP() << "TRESCA_ISA=" << forced << " chooses by hand";
  ASSERT_FALSE(isa_variants().empty());
  EXPECT_EQ(&isa(), isa_variants().front());
  EXPECT_STREQ(isa_variants().back()->id, "baseline");
#if defined(__x86_64__)
  __builtin_cpu_init();
  if (__builtin_cpu_supports("x86-64-v4")) {
    EXPECT_EQ(isa().vector_bytes, 64) << build_info();
    EXPECT_STREQ(isa().id, "x86-64-v4");
  } else {
    EXPECT_EQ(isa_variants().size(), 1u) << build_info();
  }
#endif
  for (const IsaKernels* v : isa_variants()) EXPECT_GE(v->vector_bytes, 8) << v->id;
}

}  // namespace tresca
