#include "core/parallel/slab.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "kernels/vector_ops.hpp"

namespace tresca {

unsigned Slab::local_faces(unsigned global_faces) const {
  unsigned f = global_faces;
  if (lo) f &= ~unsigned(kFaceY0);
  if (hi) f &= ~unsigned(kFaceY1);
  return f;
}

Slab make_slab(const GridDims& g, int rank, int ranks) {
  const index ny = g.ny();
  if (ranks < 1 || rank < 0 || rank >= ranks)
    throw std::invalid_argument("make_slab: rank " + std::to_string(rank) + " of " + std::to_string(ranks));
  if (ny < ranks)
    throw std::invalid_argument("the mesh has " + std::to_string(ny) + " node rows in y, fewer than the " +
                                std::to_string(ranks) + " ranks: use fewer ranks or a finer mesh");
  Slab s;
  s.global = g;
  s.rank = rank;
  s.ranks = ranks;
  const index base = ny / ranks, extra = ny % ranks;
  s.y_begin = rank * base + std::min<index>(rank, extra);
  s.y_end = s.y_begin + base + (rank < extra ? 1 : 0);
  s.lo = rank > 0 ? 1 : 0;
  s.hi = rank + 1 < ranks ? 1 : 0;
  s.local = g;
  if (ranks == 1) return s;
  s.local = rows_box(g, s.y_begin - s.lo, s.y_end + s.hi);
  return s;
}

namespace {
// copies `rows` node rows of all planes and components between two SoA
// vectors whose grids differ only in y: from row src_row of a to row dst_row of b
void copy_rows(const GridDims& ga, const real* a, index src_row, const GridDims& gb, real* b, index dst_row, index rows) {
  const index nx = ga.nx(), Na = ga.nodes(), Nb = gb.nodes();
  for (int c = 0; c < 3; ++c)
    for (index iz = 0; iz < ga.nz(); ++iz)
      copy(nx * rows, a + c * Na + ga.node(0, src_row, iz), b + c * Nb + gb.node(0, dst_row, iz));
}
}  // namespace

void global_to_local(const Slab& s, const real* global, real* local) {
  const index first = s.y_begin - s.lo, rows = s.owned_rows() + s.lo + s.hi;
  copy_rows(s.global, global, first, s.local, local, 0, rows);
}

void local_to_global(const Slab& s, const real* local, real* global) {
  copy_rows(s.local, local, s.lo, s.global, global, s.y_begin, s.owned_rows());
}

}  // namespace tresca
