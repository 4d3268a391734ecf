// The interior elasticity problem K_ii u = l_i (u = 0 on x = 0 and on the
// contact face) solved by multigrid-preconditioned CG: the smallest
// end-to-end use of mesh, kernels and inner solver (elastic driver,
// mg_scaling, tests). The residual is recomputed independently after the solve.
#pragma once
#include <vector>

#include "core/solvers/cg.hpp"
#include "core/solvers/multigrid.hpp"
#include "core/fem/problem.hpp"

namespace tresca {

struct InteriorSolution {
  std::vector<real> u;             // 3N SoA
  SolveStats stats;
  double fine_matvecs = 0;         // work: per CG iteration one apply of K_ii and one V-cycle
  real relative_residual = 0;      // ||l_i - K_ii u|| / ||l_i||, recomputed
  double seconds = 0;
};

// mg must be the K_ii hierarchy of P (faces P.interior_faces).
InteriorSolution solve_interior_elasticity(const Problem& P, const Multigrid& mg, real rtol);

}  // namespace tresca
