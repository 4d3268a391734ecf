// Symmetric 3x3 blocks on the bottom face (iz = 0), the boundary term of the
// Newton-step preconditioner (method.md §4, H and the fixed-dof penalties):
//
//   (B x)(n) = B(n) x(n),  B = [[bxx, bxy, 0], [bxy, byy, 0], [0, 0, bzz]]
//
// DATA LAYOUT: B is 4 consecutive fields of nx*ny values (bxx, bxy, byy, bzz)
// indexed by ix + nx*iy; x, y are SoA grid fields (grid.hpp).
// Cost per bottom node: reads 4 B fields, 3 x and 3 y, writes 3 y; 13 flops.
#pragma once
#include "apply_out.hpp"
#include "grid.hpp"

namespace tresca {

constexpr Cost kBottomBlockCost{104, 13};  // per bottom-face node

// T = double or float (B, x and out's vectors all of T). As the last part of an apply whose stencil part is done (apply_out.hpp):
// each bottom entry as if `out` had been given v + (B x)_j: y += B x for the
// operator, y -= B x for the residual, and for the Chebyshev step the new
// iterate less t dinv (B x).
template <class T>
void bottom_block_apply(const GridDims& g, const T* B, const T* x, const ApplyOut<T>& out);
// the _ref twin (double): y += alpha B x
void bottom_block_apply_ref(const GridDims& g, real alpha, const real* B, const real* x, real* y);
// d += diag(B) on the bottom face (the Jacobi diagonal of K + B)
void bottom_block_diagonal(const GridDims& g, const real* B, real* d);

}  // namespace tresca
