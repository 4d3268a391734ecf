// Structured node grid of a box discretised by ex*ey*ez congruent bricks.
//
// DATA LAYOUT ASSUMPTIONS
//   node (ix,iy,iz), 0 <= ix < nx = ex+1 (same for y, z), has the flat index
//   n = ix + nx*(iy + ny*iz).  Vector fields are structure-of-arrays:
//   component c of node n lives at v[c*N + n], N = nx*ny*nz.
//   Constrained (Dirichlet) dofs are whole faces of the box, all 3 components,
//   given as a bitmask of Face values.
#pragma once
#include "types.hpp"

namespace tresca {

enum Face : unsigned { kFaceX0 = 1u, kFaceX1 = 2u, kFaceY0 = 4u, kFaceY1 = 8u, kFaceZ0 = 16u, kFaceZ1 = 32u };

struct GridDims {
  index ex = 1, ey = 1, ez = 1;       // elements per axis
  real lx = 1, ly = 1, lz = 1;        // box edge lengths
  real x0 = 0, y0 = 0, z0 = 0;        // box origin

  index nx() const { return ex + 1; }
  index ny() const { return ey + 1; }
  index nz() const { return ez + 1; }
  index nodes() const { return nx() * ny() * nz(); }
  index node(index ix, index iy, index iz) const { return ix + nx() * (iy + ny() * iz); }
  real hx() const { return lx / real(ex); }
  real hy() const { return ly / real(ey); }
  real hz() const { return lz / real(ez); }
};

// The node rows [a, b) of g (all of x and z) as a grid of their own: the same
// spacing up to rounding of ly / ey (operators on a part of a larger grid
// take that grid's spacing: build_elasticity_stencil's h).
inline GridDims rows_box(const GridDims& g, index a, index b) {
  GridDims r = g;
  r.ey = b - a - 1;
  r.y0 = g.y0 + real(a) * g.hy();
  r.ly = g.hy() * real(r.ey);
  return r;
}

// Which nodes of the node row (iy, iz) of g lie on a face in `faces`: the
// whole row where it lies on a y or z face, else its ends on x faces
// (node_constrained below, a row at a time).
struct ConstrainedRow {
  bool whole, x0, x1;
  index last;  // the row's last node, ex
  ConstrainedRow(const GridDims& g, unsigned faces, index iy, index iz)
      : whole(((faces & kFaceY0) && iy == 0) || ((faces & kFaceY1) && iy == g.ey) ||
              ((faces & kFaceZ0) && iz == 0) || ((faces & kFaceZ1) && iz == g.ez)),
        x0(faces & kFaceX0), x1(faces & kFaceX1), last(g.ex) {}
  // (bitwise, no branch: a select in a vectorised loop)
  bool at(index ix) const { return whole | (x0 & (ix == 0)) | (x1 & (ix == last)); }
};

// Is node (ix,iy,iz) on a constrained face?
inline bool node_constrained(const GridDims& g, unsigned faces, index ix, index iy, index iz) {
  return ((faces & kFaceX0) && ix == 0) || ((faces & kFaceX1) && ix == g.ex) ||
         ((faces & kFaceY0) && iy == 0) || ((faces & kFaceY1) && iy == g.ey) ||
         ((faces & kFaceZ0) && iz == 0) || ((faces & kFaceZ1) && iz == g.ez);
}

}  // namespace tresca
