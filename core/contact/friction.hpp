// The friction law of a run, one value:
//
// * Tresca: the bound phi_i per contact node is given
//   (ContactConditions::phi);
// * Coulomb: phi_i = F lambda_i with coefficient F >= 0, and how the solver
//   treats that bound (measured on levels 5-11, perf/RESULTS.md §0e):
//   - newton (default): one Newton solve whose step differentiates
//     phi = F lambda (a sliding node's friction force F lambda t moves with
//     lambda): the semismooth* Newton step of the Coulomb problem itself,
//     not symmetric, solved by boundary GMRES;
//   - lagged: one Newton solve with the bound set from lambda before every
//     approximation step, not differentiated (a symmetric quasi-Newton step);
//   - fixed_point: whole Tresca solves, the bound updated between them
//     (coulomb.hpp).
#pragma once
#include <string>

#include "kernels/types.hpp"

namespace tresca {

struct FrictionLaw {
  enum class Kind { tresca, coulomb };
  enum class CoulombMethod { newton, lagged, fixed_point };
  Kind kind = Kind::tresca;
  real F = 0;  // Coulomb's coefficient
  CoulombMethod method = CoulombMethod::newton;

  bool is_coulomb() const { return kind == Kind::coulomb; }
  // inside one Newton solve: the bound is F lambda of the current iterate
  bool bound_follows_lambda() const { return is_coulomb() && method != CoulombMethod::fixed_point; }
  // ... and the Newton step differentiates it
  bool differentiates_bound() const { return is_coulomb() && method == CoulombMethod::newton; }
  // "Tresca" or "Coulomb F 0.8 (newton)"
  std::string describe() const;
};

FrictionLaw tresca_friction();
// throws std::invalid_argument unless F >= 0 and finite
FrictionLaw coulomb_friction(real F, FrictionLaw::CoulombMethod method = FrictionLaw::CoulombMethod::newton);

const char* to_string(FrictionLaw::CoulombMethod m);  // "newton", "lagged", "fixed_point"
// "lagged", "newton" or "fixed-point" (also "fixed_point"); throws
// std::invalid_argument naming `option` otherwise
FrictionLaw::CoulombMethod coulomb_method_from(const std::string& s, const std::string& option);

}  // namespace tresca
