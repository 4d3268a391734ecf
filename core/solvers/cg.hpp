// Preconditioned conjugate gradients for SPD A with SPD preconditioner M ≈ A^{-1}.
//
// Stops when ||r|| <= max(rtol*||b||, atol) (Euclidean norm of the true
// recursive residual), or returns the reason it could not: max_iterations,
// breakdown (p.Ap <= 0 or r.z <= 0: operator or preconditioner not SPD),
// non_finite (NaN/Inf appeared), or aborted (the caller's abort_if said so,
// e.g. an inexactly applied operator failed). It never loops beyond
// max_iterations.
//
// Per iteration: 1 apply of A, 1 of M, 2 dots + 1 fused update + 1 xpay:
// vector traffic 104 bytes and 14 flops per entry besides A and M. An M
// that works in float (operator.hpp) takes r's float copy, which the update
// writes, and its z is read in float by the dot and the xpay: 100 bytes,
// where M's own conversions of r and z would add 24 to the 104.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "core/solvers/operator.hpp"
#include "kernels/launch.hpp"
#include "core/util/reduction.hpp"

namespace tresca {

enum class SolveReason { converged, max_iterations, breakdown, non_finite, aborted };
const char* to_string(SolveReason r);

struct SolveStats {
  int iterations = 0;
  int operator_applications = 0;        // applications of A (the work, with those of M)
  int preconditioner_applications = 0;  // applications of M
  real residual = 0;          // final ||r||
  real initial_residual = 0;  // ||b - A x0||
  real rhs_norm = 0;          // ||b||
  SolveReason reason = SolveReason::converged;
  bool ok() const { return reason == SolveReason::converged; }
};

struct CGOptions {
  real rtol = 1e-10;
  real atol = 0;
  int max_iterations = 1000;
  bool zero_initial_guess = true;  // otherwise x holds the initial guess
  // with a side product: side_x += B x onto the caller's side_x (otherwise
  // side_x = B x), e.g. onto B x_known of a part of the solution known before
  bool side_adds = false;
  // called with ||r|| of the initial residual and after every update (lets an
  // inexactly applied A relax its accuracy as the residual falls)
  std::function<void(real rnorm)> on_residual;
  // checked after every application of A; true stops with reason aborted
  std::function<bool()> abort_if;
  // the parts over which the vectors are distributed (the ranks of a run,
  // core/util/reduction.hpp): every dot product is the sum of the parts'
  // local ones. Null: one part.
  const Reduction* reduction = nullptr;
};

// Work vectors kept by the caller so repeated solves do not allocate (z,
// or r_low and z_low for a preconditioner that works in float).
struct CGWorkspace {
  Field<real> r, z, p, q, s;
  Field<float> r_low, z_low;
};

SolveStats pcg(const LinearOperator& A, const LinearOperator* M, const real* b, real* x, const CGOptions& opt,
               CGWorkspace& ws);
// The same, and side_x = B x for the solution x (operator.hpp; side_adds:
// side_x += B x): B p comes with every A p, and side_x += alpha B p with
// every step x += alpha p.
SolveStats pcg(const LinearOperatorWithSide& A, const LinearOperator* M, const real* b, real* x, real* side_x,
               const CGOptions& opt, CGWorkspace& ws);

}  // namespace tresca
