// Decomposition of the structured grid into slabs of node rows along y, one
// per rank (MPI phase 1, issue 12). y, not z: the contact face is the bottom
// plane z = z0, so every rank holds a strip of it; x is the clamped axis.
//
// Rank r owns the global node rows [y_begin, y_end) (balanced: the first
// ny % ranks ranks one row more) and keeps one ghost row on each side that
// has a neighbour. Its vectors live on the local box of rows
// [y_begin - lo, y_end + hi): a GridDims of its own with the same spacing
// (ly/ey may round in the last bit, so operators on it take the global
// grid's spacing), and the elasticity kernels run on it unchanged: the
// owned rows of K x come out bit for bit as on the whole grid (the same
// per-node stencils).
//
//   local row j = global row iy - (y_begin - lo);  owned: lo <= j < lo + owned_rows()
#pragma once
#include <algorithm>

#include "kernels/field.hpp"
#include "kernels/grid.hpp"

namespace tresca {

struct Slab {
  GridDims global;
  int rank = 0, ranks = 1;
  index y_begin = 0, y_end = 0;  // owned node rows of the global grid
  index lo = 0, hi = 0;          // ghost rows below / above (0 or 1)
  GridDims local;                // rows [y_begin - lo, y_end + hi)
  index owned_rows() const { return y_end - y_begin; }
  index local_row(index global_iy) const { return global_iy - (y_begin - lo); }
  // constrained faces of the local box: the global ones, without y faces
  // that are a neighbour's
  unsigned local_faces(unsigned global_faces) const;
};

// rank's slab of g among `ranks`; throws std::invalid_argument if there are
// fewer node rows than ranks
Slab make_slab(const GridDims& g, int rank, int ranks);

// Rows [r0, r1) of all planes and components of a SoA vector on grid g to
// a packed buffer (component, plane, then the rows' nodes), and back: the
// messages of ghost exchanges and row fetches. T = double or float.
template <class T>
void rows_to_buffer(const GridDims& g, const T* v, index r0, index r1, T* buf) {
  const index N = g.nodes(), len = (r1 - r0) * g.nx();
  for (int c = 0; c < 3; ++c)
    for (index iz = 0; iz < g.nz(); ++iz, buf += len) std::copy_n(v + c * N + g.node(0, r0, iz), len, buf);
}
template <class T>
void buffer_to_rows(const GridDims& g, const T* buf, index r0, index r1, T* v) {
  const index N = g.nodes(), len = (r1 - r0) * g.nx();
  for (int c = 0; c < 3; ++c)
    for (index iz = 0; iz < g.nz(); ++iz, buf += len) std::copy_n(buf, len, v + c * N + g.node(0, r0, iz));
}

// SoA (3 components) global vector -> rank's local vector (owned and ghost rows)
void global_to_local(const Slab& s, const real* global, real* local);
// the owned rows of a local vector -> their places in a global vector (other rows untouched)
void local_to_global(const Slab& s, const real* local, real* global);

}  // namespace tresca
