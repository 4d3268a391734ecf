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

}  // namespace tresca
