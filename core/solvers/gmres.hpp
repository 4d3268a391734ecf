// Restarted GMRES(m) with right preconditioning, for non-symmetric A (the
// Coulomb Newton step, whose friction bound depends on the contact force, is
// not symmetric; method.md §4 is the symmetric Tresca case).
//
// Solves A x = b with the Krylov space of A M, x = x0 + M y, so the monitored
// residual is the true ||b − A x|| (no preconditioner in the norm). Arnoldi by
// modified Gram–Schmidt, least squares by Givens rotations. Stops when
// ||r|| <= max(rtol*||b||, atol), or returns the reason it could not:
// max_iterations (total inner steps), breakdown (the Krylov space became
// invariant without solving: singular A or M), non_finite. A "happy"
// breakdown that solves the system is convergence. The residual is recomputed
// as b − A x at every restart, so round-off in the recursion cannot hide.
//
// Memory: m + 1 basis vectors and m preconditioned vectors of length n (flexible
// storage, so M may vary between applications). Work per inner step: 1 apply
// of A and of M, j + 1 dots and axpys of length n at step j.
#pragma once
#include <functional>
#include <vector>

#include "core/solvers/cg.hpp"

namespace tresca {

struct GMRESOptions {
  real rtol = 1e-10;
  real atol = 0;
  int restart = 30;           // m
  int max_iterations = 1000;  // inner steps over all cycles
  bool zero_initial_guess = true;
  // polled after each application of A: true stops with `aborted` (e.g. an
  // inexact A whose own inner solve failed)
  std::function<bool()> abort_if;
  // the parts the vectors are distributed over (as CGOptions::reduction); null: one part
  const Reduction* reduction = nullptr;
};

SolveStats gmres(const LinearOperator& A, const LinearOperator* M, const real* b, real* x, const GMRESOptions& opt);

}  // namespace tresca
