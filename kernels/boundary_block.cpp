#include "boundary_block.hpp"

#include "launch.hpp"

namespace tresca {

template <class T>
void bottom_block_apply(const GridDims& g, const T* B, const T* x, const ApplyOut<T>& out) {
  const index M = g.nx() * g.ny(), N = g.nodes();
  const T *bxx = B, *bxy = B + M, *byy = B + 2 * M, *bzz = B + 3 * M;
  const Cost step = is_step(kind(out)) ? kChebStepExtraCost : Cost{};  // the Chebyshev step's dinv and y
  const char* name = precision_name<T>("bottom block", "bottom block (float)");
  with_kind(out, [&](auto kind) {
    constexpr OutKind K = decltype(kind)::value;
    for_each_entry(name, M, in_precision<T>(kBottomBlockCost + step), [=](index n) {
      const T ux = x[n], uy = x[N + n], uz = x[2 * N + n];
      add<K>(out, n, bxx[n] * ux + bxy[n] * uy);
      add<K>(out, N + n, bxy[n] * ux + byy[n] * uy);
      add<K>(out, 2 * N + n, bzz[n] * uz);
    });
  });
}
template void bottom_block_apply<double>(const GridDims&, const double*, const double*, const ApplyOut<double>&);
template void bottom_block_apply<float>(const GridDims&, const float*, const float*, const ApplyOut<float>&);

void bottom_block_diagonal(const GridDims& g, const real* B, real* d) {
  const index M = g.nx() * g.ny(), N = g.nodes();
  for_each_entry("bottom block diagonal", M, Cost{72, 3}, [=](index n) {
    d[n] += B[n];
    d[N + n] += B[2 * M + n];
    d[2 * N + n] += B[3 * M + n];
  });
}

void bottom_block_apply_ref(const GridDims& g, real alpha, const real* B, const real* x, real* y) {
  const index M = g.nx() * g.ny(), N = g.nodes();
  for (index n = 0; n < M; ++n) {
    const real b[3][3] = {{B[n], B[M + n], 0}, {B[M + n], B[2 * M + n], 0}, {0, 0, B[3 * M + n]}};
    for (int a = 0; a < 3; ++a)
      for (int c = 0; c < 3; ++c) y[a * N + n] += alpha * b[a][c] * x[c * N + n];
  }
}

}  // namespace tresca
