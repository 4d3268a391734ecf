#include "core/fem/assembly.hpp"

#include <stdexcept>
#include <string>
#include <vector>

namespace tresca {

SparseMatrix assemble_stiffness(const ElasticityOperator& op) {
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
  SparseMatrix A(3 * N, 3 * N);
  A.setFromTriplets(t.begin(), t.end());
  A.prune(0.0);
  return A;
}

SparseMatrix assemble_bottom_block(const GridDims& g, const std::vector<real>& B) {
  const index N = g.nodes(), M = g.nx() * g.ny();
  SparseMatrix A(3 * N, 3 * N);
  if (B.empty()) return A;
  if (index(B.size()) != 4 * M)
    throw std::invalid_argument("assemble_bottom_block: " + std::to_string(B.size()) + " entries, expected 4 x " +
                                std::to_string(M));
  std::vector<Eigen::Triplet<real, index>> t;
  t.reserve(std::size_t(5 * M));
  for (index n = 0; n < M; ++n) {  // (the bottom plane's nodes are the grid's first M)
    t.emplace_back(n, n, B[n]);
    t.emplace_back(n, N + n, B[M + n]);
    t.emplace_back(N + n, n, B[M + n]);
    t.emplace_back(N + n, N + n, B[2 * M + n]);
    t.emplace_back(2 * N + n, 2 * N + n, B[3 * M + n]);
  }
  A.setFromTriplets(t.begin(), t.end());
  return A;
}

std::vector<index> bottom_block_dofs(const GridDims& g, unsigned faces) {
  const index N = g.nodes();
  std::vector<index> dofs;
  for (int a = 0; a < 3; ++a)
    for (index iy = 0; iy < g.ny(); ++iy)
      for (index ix = 0; ix < g.nx(); ++ix)
        if (!node_constrained(g, faces, ix, iy, 0)) dofs.push_back(a * N + g.node(ix, iy, 0));
  return dofs;
}

SparseMatrix assemble(const ElasticityOperator& op) {
  SparseMatrix A = assemble_stiffness(op);
  if (!op.bottom_block().empty()) A += assemble_bottom_block(op.grid(), op.bottom_block().to_vector());
  A.prune(0.0);
  return A;
}

}  // namespace tresca
