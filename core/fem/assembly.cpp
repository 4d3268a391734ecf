#include "core/fem/assembly.hpp"

#include <vector>

namespace tresca {

SparseMatrix assemble(const ElasticityOperator& op) {
  const GridDims& g = op.grid();
  const ElasticityStencil& k = op.stencil();
  const index N = g.nodes();
  std::vector<Eigen::Triplet<real, index>> t;
  t.reserve(size_t(g.ex * g.ey * g.ez) * 576);
  for (index ez = 0; ez < g.ez; ++ez)
    for (index ey = 0; ey < g.ey; ++ey)
      for (index ex = 0; ex < g.ex; ++ex) {
        index nodes[8];
        bool fixed[8];
        for (int L = 0; L < 8; ++L) {
          const index ix = ex + (L & 1), iy = ey + ((L >> 1) & 1), iz = ez + ((L >> 2) & 1);
          nodes[L] = g.node(ix, iy, iz);
          fixed[L] = node_constrained(g, op.faces(), ix, iy, iz);
        }
        for (int L = 0; L < 8; ++L)
          for (int M = 0; M < 8; ++M) {
            if (fixed[L] || fixed[M]) continue;
            for (int a = 0; a < 3; ++a)
              for (int b = 0; b < 3; ++b)
                t.emplace_back(a * N + nodes[L], b * N + nodes[M], k.Ke[24 * (3 * L + a) + 3 * M + b]);
          }
      }
  for (index iz = 0; iz < g.nz(); ++iz)
    for (index iy = 0; iy < g.ny(); ++iy)
      for (index ix = 0; ix < g.nx(); ++ix)
        if (node_constrained(g, op.faces(), ix, iy, iz))
          for (int a = 0; a < 3; ++a) t.emplace_back(a * N + g.node(ix, iy, iz), a * N + g.node(ix, iy, iz), 1.0);
  const std::vector<real> B = op.bottom_block().to_vector();  // (wherever it lives)
  if (!B.empty()) {
    const index M = g.nx() * g.ny();
    for (index n = 0; n < M; ++n) {
      t.emplace_back(n, n, B[n]);
      t.emplace_back(n, N + n, B[M + n]);
      t.emplace_back(N + n, n, B[M + n]);
      t.emplace_back(N + n, N + n, B[2 * M + n]);
      t.emplace_back(2 * N + n, 2 * N + n, B[3 * M + n]);
    }
  }
  SparseMatrix A(3 * N, 3 * N);
  A.setFromTriplets(t.begin(), t.end());
  A.prune(0.0);
  return A;
}

}  // namespace tresca
