#include "core/contact/friction.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace tresca {

FrictionLaw tresca_friction() { return {}; }

FrictionLaw coulomb_friction(real F, FrictionLaw::CoulombMethod method) {
  if (!(F >= 0) || !std::isfinite(F))
    throw std::invalid_argument("the Coulomb friction coefficient " + std::to_string(F) + " must be >= 0 and finite");
  FrictionLaw f;
  f.kind = FrictionLaw::Kind::coulomb;
  f.F = F;
  f.method = method;
  return f;
}

std::string FrictionLaw::describe() const {
  if (!is_coulomb()) return "Tresca";
  std::ostringstream os;
  os << "Coulomb F " << F << " (" << to_string(method) << ")";
  return os.str();
}

const char* to_string(FrictionLaw::CoulombMethod m) {
  switch (m) {
    case FrictionLaw::CoulombMethod::lagged: return "lagged";
    case FrictionLaw::CoulombMethod::newton: return "newton";
    case FrictionLaw::CoulombMethod::fixed_point: return "fixed_point";
  }
  return "?";
}

FrictionLaw::CoulombMethod coulomb_method_from(const std::string& s, const std::string& option) {
  if (s == "lagged") return FrictionLaw::CoulombMethod::lagged;
  if (s == "newton") return FrictionLaw::CoulombMethod::newton;
  if (s == "fixed-point" || s == "fixed_point") return FrictionLaw::CoulombMethod::fixed_point;
  throw std::invalid_argument(option + " '" + s + "' must be newton, lagged or fixed-point");
}

}  // namespace tresca
