// Stiffness of one trilinear (Q1) brick of size hx*hy*hz, isotropic linear
// elasticity (Young's modulus E, Poisson ratio nu), full 2x2x2 Gauss rule:
//
//   Ke = sum_g B(xi_g)^T D B(xi_g) det J w_g,
//
// B the 6x24 strain-displacement matrix (Voigt order xx,yy,zz,xy,yz,xz with
// engineering shears), D = lambda 1 1^T + mu diag(2,2,2,1,1,1).
//
// DATA LAYOUT: local node L = lx + 2*ly + 4*lz (lx,ly,lz in {0,1}); element
// dof 3*L + c; Ke is row-major 24x24.
#pragma once
#include "types.hpp"

namespace tresca {

struct Lame {
  real lambda, mu;
};
Lame lame_from(real E, real nu);

// Writes the 576 entries of Ke.
void brick_stiffness(real hx, real hy, real hz, real E, real nu, real* Ke);

// Cauchy stress at the brick's centroid from its 24 nodal displacements ue
// (layout above): s = D B(0) ue in VTK's order of a symmetric tensor,
// xx, yy, zz, xy, yz, xz [Pa]. At the centroid du/dx is the mean of the four
// x-edge differences over hx (likewise y, z): exact for the Q1 field there.
void centroid_stress(real hx, real hy, real hz, real E, real nu, const real* ue, real* s);
// von Mises equivalent stress of s (the order above)
real von_mises(const real* s);

}  // namespace tresca
