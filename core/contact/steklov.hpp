// The contact Steklov–Poincaré operator and condensed load (method.md §2),
// applied matrix-free, never formed:
//
//   S v = K_cc v − K_ci K_ii^{-1} K_ic v = (K E v)_c ,
//   b̃  = l_c − K_ci K_ii^{-1} l_i ,
//   u_i = K_ii^{-1} (l_i − K_ic u_c)            (interior recovery)
//
// where E v = w + z is the discrete harmonic extension: w = v on the contact
// face (zero elsewhere) and K_ii z = −K_ic v. K has u = 0 on x = 0; K_ii also
// on the contact face z = z0. K_ii is solved by CG preconditioned with one
// geometric-multigrid V-cycle (multigrid.hpp). Because w lives on the bottom
// plane, K_ic v needs K only on plane iz = 1 and (K E v)_c only on iz = 0.
//
// DATA LAYOUT: contact vectors are SoA of 3 blocks of p values
// [u_x(0..p-1) | u_y | u_z], contact node c as in problem.hpp.
// Cost per apply: one inner MG-CG solve (dominant) + 2 plane applies.
#pragma once
#include <vector>

#include "core/solvers/cg.hpp"
#include "core/solvers/multigrid.hpp"
#include "core/fem/problem.hpp"

namespace tresca {

struct InnerStats {
  long long solves = 0, iterations = 0, failures = 0;
  SolveReason last_failure = SolveReason::converged;
};

class SteklovPoincare : public LinearOperator {
 public:
  SteklovPoincare(const Problem& P, const MGOptions& mg = {});
  index size() const override { return 3 * p_; }
  void apply(const real* v, real* Sv) const override;

  // b̃ with an inner solve to relative tolerance rtol
  std::vector<real> condensed_load(real rtol) const;
  // full SoA displacement (3N) from contact values u_c
  std::vector<real> recover(const real* uc, real rtol) const;

  // relative tolerance of the inner solve in apply (may be changed between applies)
  void set_inner_rtol(real r) const { inner_rtol_ = r; }
  real inner_rtol() const { return inner_rtol_; }
  const InnerStats& stats() const { return stats_; }
  const Multigrid& interior_multigrid() const { return mg_; }  // its options() also serve the Newton step
  const ElasticityOperator& K() const { return K_; }
  const Problem& problem() const { return P_; }

  // scatter contact values into / gather them from a full SoA grid vector
  void scatter(const real* vc, real* full) const;
  void gather(const real* full, real* vc) const;

 private:
  SolveStats solve_interior(const real* rhs, real* z) const;
  // plane iz of all 3 components of v := src's (or 0 if src is null)
  void set_plane(real* v, index iz, const real* src) const;

  const Problem& P_;
  index p_;
  ElasticityOperator K_;       // faces x0
  Multigrid mg_;               // K_ii hierarchy, faces x0 | z0
  mutable real inner_rtol_ = 1e-10;
  mutable InnerStats stats_;
  mutable CGWorkspace ws_;
  mutable std::vector<real> w_, t_, z_;
};

}  // namespace tresca
