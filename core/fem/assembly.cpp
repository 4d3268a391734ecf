#include "core/fem/assembly.hpp"

#include <stdexcept>
#include <string>
#include <vector>

namespace tresca {

SparseMatrix assemble_stiffness(const ElasticityOperator& op) {
  // Column by column (dof b of node m, in order), each from the up to 8
  // elements around m, in the order of their index (the sums of an
  // element-by-element assembly, bit for bit), into the column's up to 3 x 27
  // rows (component a of each neighbour n = m + off[d], in order), without
  // the sort of a triplet list (RESULTS.md §0zk)
  const GridDims& g = op.grid();
  const ElasticityStencil& k = op.stencil();
  const index N = g.nodes(), nx = g.nx(), ny = g.ny();
  std::vector<char> fixed(static_cast<std::size_t>(N));
  for (index iz = 0; iz < g.nz(); ++iz)
    for (index iy = 0; iy < ny; ++iy)
      for (index ix = 0; ix < nx; ++ix)
        fixed[std::size_t(g.node(ix, iy, iz))] = node_constrained(g, op.faces(), ix, iy, iz);
  index off[27];  // neighbour d = 9 (dz + 1) + 3 (dy + 1) + dx + 1 at node offset off[d], increasing
  for (int d = 0; d < 27; ++d) off[d] = (d % 3 - 1) + nx * ((d / 3) % 3 - 1) + nx * ny * (d / 9 - 1);
  SparseMatrix A(3 * N, 3 * N);
  A.reserve(std::size_t(3 * N) * 81);
  for (int b = 0; b < 3; ++b)
    for (index m = 0; m < N; ++m) {
      const index col = b * N + m;
      A.startVec(col);
      if (fixed[std::size_t(m)]) {  // (a constrained dof: its identity row and column)
        A.insertBack(col, col) = 1.0;
        continue;
      }
      const index ix = m % nx, iy = (m / nx) % ny, iz = m / (nx * ny);
      real acc[3][27] = {};
      bool near[27] = {};
      for (int sz = 1; sz >= 0; --sz)  // (elements in index order)
        for (int sy = 1; sy >= 0; --sy)
          for (int sx = 1; sx >= 0; --sx) {
            const index ex = ix - sx, ey = iy - sy, ez = iz - sz;
            if (ex < 0 || ey < 0 || ez < 0 || ex >= g.ex || ey >= g.ey || ez >= g.ez) continue;
            const int Lm = sx + 2 * sy + 4 * sz;  // m's corner of the element
            for (int Ln = 0; Ln < 8; ++Ln) {
              const int dx = (Ln & 1) - sx, dy = ((Ln >> 1) & 1) - sy, dz = ((Ln >> 2) & 1) - sz;
              const int d = 9 * (dz + 1) + 3 * (dy + 1) + dx + 1;
              if (fixed[std::size_t(m + off[d])]) continue;
              near[d] = true;
              for (int a = 0; a < 3; ++a) acc[a][d] += k.Ke[24 * (3 * Ln + a) + 3 * Lm + b];
            }
          }
      for (int a = 0; a < 3; ++a)
        for (int d = 0; d < 27; ++d)
          if (near[d] && acc[a][d] != 0) A.insertBack(a * N + m + off[d], col) = acc[a][d];
    }
  A.finalize();
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
