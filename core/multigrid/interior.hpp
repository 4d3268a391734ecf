// The interior elasticity problem K_ii u = l_i (u = 0 on x = 0 and on the
// contact face) solved by multigrid-preconditioned CG: the smallest
// end-to-end use of mesh, kernels and inner solver (elastic driver,
// mg_scaling, tests). The residual is recomputed independently after the solve.
// On one rank or many: the vectors are mg's level-0 vectors (this rank's
// slab of the grid).
#pragma once
#include <vector>

#include "core/solvers/cg.hpp"
#include "core/multigrid/multigrid.hpp"
#include "core/fem/problem.hpp"

namespace tresca {

struct InteriorSolution {
  Field<real> u;             // 3N SoA on this rank's slab (ghost rows 0)
  SolveStats stats;
  double fine_matvecs = 0;         // work: per CG iteration one apply of K_ii and one V-cycle
  real relative_residual = 0;      // ||l_i - K_ii u|| / ||l_i||, recomputed
  real max_abs_u = 0;              // over every rank
  double seconds = 0;
};

// mg must be the K_ii multigrid of P (faces P.interior_faces) on any ranks.
InteriorSolution solve_interior_elasticity(const Problem& P, const Multigrid& mg, real rtol);

}  // namespace tresca
