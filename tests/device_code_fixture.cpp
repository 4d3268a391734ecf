// The three patterns tests/check_device_code.py keeps out of the GPU code:
// a launch body that passes local arrays on to a function and reads them
// back in a loop, which GCC 12 miscompiled for the GPU (as the Newton-step
// operator had it), a target region that maps a value, which costs a
// launch 1.5 ms in GCC 12's libgomp, and a teams region with a
// thread_limit, which costs each team a malloc on the device. The program
// exists to be scanned (`check_device_code.py --expect-flagged`): all three
// must be flagged, or the checks no longer see what they guard against.
// Run, it says whether its first result is right (on the host it is; on a
// GPU it was not).
#include <cstdio>
#include <vector>

#include "kernels/launch.hpp"

namespace {
struct View {
  const double* h;
  const unsigned char* free;
  bool coupled;
};
// y = sx + (the node's 2x2 block of h) x, as the Newton-step operator's rows
inline void rows(tresca::index p, tresca::index i, const double sx[3], const double* x, const View& L, double y[3]) {
  y[0] = sx[0] + L.h[i] * x[i] + L.h[p + i] * x[p + i];
  y[1] = sx[1] + L.h[p + i] * x[i] + L.h[2 * p + i] * x[p + i];
  y[2] = sx[2];
  if (L.coupled) y[0] += L.h[i] * y[2];
}
}  // namespace

int main() {
  using tresca::index;
  const index p = 1000;
  tresca::Field<double> h(3 * p, 1.0), x(3 * p, 1.0), sx(3 * p, 1.0), out(3 * p);
  tresca::Field<unsigned char> free(3 * p, 1);
  const View L{h.data(), free.data(), false};
  const double *xs = x.data(), *s = sx.data();
  double* y = out.data();
  tresca::for_each_entry("fixture", p, tresca::Cost{80, 10}, [=](index i) {
    const double si[3] = {s[i], s[p + i], s[2 * p + i]};
    double yi[3];
    rows(p, i, si, xs, L, yi);
    for (int a = 0; a < 3; ++a) y[a * p + i] = L.free[a * p + i] ? yi[a] : 0;
  });
  const std::vector<double> r = out.to_vector();
  double mapped = 0;  // a region that maps a value
#pragma omp target map(tofrom : mapped)
  mapped = 1;
  // and one that names its team size, which costs every team a malloc on
  // the device (GOMP_teams4, kernels/launch.hpp)
#pragma omp target teams thread_limit(4)
  {
  }
  const bool ok = r[7] == 3.0 && r[p + 7] == 3.0 && r[2 * p + 7] == 1.0 && mapped == 1;
  std::printf("fixture: rows of node 7 = (%g, %g, %g) (3, 3, 1 expected): %s\n", r[7], r[p + 7], r[2 * p + 7],
              ok ? "ok" : "WRONG");
  return ok ? 0 : 1;
}
