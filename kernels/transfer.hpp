// Grid transfers between two uniform grids of the same box (non-nested in
// general: coarse e = ceil(fine e / 2) per axis).
//
//   prolongate:  u_f(x_i) = sum_J w_J(x_i) u_c(X_J)   (trilinear interpolation)
//   restrict:    r_c = P^T r_f                          (exact transpose)
//
// P is a tensor product P = Pz ⊗ Py ⊗ Px of 1D interpolations, each row with
// at most two nonzeros. The optimised kernels are gathers (race-free, OpenMP
// over output rows): prolongation combines, per fine row, the 4 coarse rows
// of its y/z support into a coarse-length row buffer (vectorised) and then
// interpolates along x from it; restriction sums, per coarse row, the
// weighted fine rows of its y/z support into a row buffer (vectorised, four
// rows a pass) and then gathers along x. Along x, where the axis halves (the
// multigrid's transfers), two fine nodes share one coarse interval: a lane
// per pair of fine nodes, contiguous reads; elsewhere (a mesh of another
// level's) the 1D lists, read indirectly. The _ref twins are the literal
// serial loops (restriction as a scatter of P^T).
//
// DATA LAYOUT: SoA fields as in grid.hpp; `comps` components of size N each.
// Cost per fine dof: prolongation 8 reads + 1 write; restriction about the same
// in total over the coarse dofs.
#pragma once
#include <vector>

#include "grid.hpp"
#include "launch.hpp"
#include "types.hpp"

namespace tresca {

// per fine dof (3 components count as 3): prolongation (accumulating) reads and
// writes the fine value plus 1/8 of a coarse one; restriction reads the fine
// value and writes 1/8 of a coarse one; 16 flops each.
constexpr Cost kProlongateCost{18.4, 16};
constexpr Cost kRestrictCost{10.4, 16};

struct Interp1D {
  // fine node i interpolates from coarse j0[i] (weight 1-w[i]) and j0[i]+1 (weight w[i])
  Field<index> j0;
  Field<real> w;
  // transpose lists: coarse j receives from fine tf[tstart[j]..tstart[j+1]) with weights tw
  Field<index> tstart, tf;
  Field<real> tw;
  // Where the axis halves (j0[i] = i/2 for every fine node, the last one
  // allowed as coarse node i/2 with weight 0 instead: every multigrid
  // transfer, coarse e = ceil(fine e / 2), nested or not), pair_w[i + 2] is
  // fine node i's weight of coarse node i/2 + 1, for i in [-2, 2 nc), 0
  // outside the fine nodes: the kernels then run along x two fine nodes to a
  // lane on contiguous reads, not one indirect read per node. Empty where
  // the axis does not halve.
  Field<real> pair_w;
  bool halving() const { return pair_w.size() > 0; }
  void move_to(Space s) {
    j0.move_to(s);
    w.move_to(s);
    tstart.move_to(s);
    tf.move_to(s);
    tw.move_to(s);
    pair_w.move_to(s);
  }
};

struct Transfer {
  GridDims fine, coarse;
  Interp1D axis[3];
  // its arrays moved to space s (field.hpp)
  void move_to(Space s) {
    for (Interp1D& a : axis) a.move_to(s);
  }
};

// built in the space where launches run (field.hpp)
Transfer build_transfer(const GridDims& fine, const GridDims& coarse);

// The part of t between fine rows [f0, f1) and coarse rows [c0, c1) (y
// only), each as a box of its own: prolongation onto a fine row is exact
// where its two coarse rows lie in [c0, c1), restriction onto a coarse row
// where its fine rows lie in [f0, f1); other rows get partial values (a
// rank's ghost rows, core/parallel). Box dims are t's with ey = rows - 1.
Transfer slice_rows(const Transfer& t, index f0, index f1, index c0, index c1);

// fine = base + P coarse (base nullptr: fine = P coarse; base may be fine
// itself: fine += P coarse), for `comps` components. The optimised kernels
// are instantiated for T = double and float. With zero_faces (Face bits of
// the output grid), the output's entries on those faces are written 0
// instead, in the same sweep: the transfer followed by
// zero_constrained(output grid, zero_faces, output), one launch.
template <class T>
void prolongate(const Transfer& t, int comps, const T* coarse, T* fine, const T* base = nullptr,
                unsigned zero_faces = 0);
void prolongate_ref(const Transfer& t, int comps, const real* coarse, real* fine, const real* base = nullptr);
// coarse = P^T fine
template <class T>
void restrict_to_coarse(const Transfer& t, int comps, const T* fine, T* coarse, unsigned zero_faces = 0);
void restrict_to_coarse_ref(const Transfer& t, int comps, const real* fine, real* coarse);

}  // namespace tresca
