#include "constraints/energy_limits.h"

#include <cmath>

namespace taut {
namespace {

// Name of the unit for messages.
const char* GetUnitName(EnergyLimitUnit unit) {
  return unit == EnergyLimitUnit::kEnergy ? "J" : "J/m^3";
}

// Throws unless value is in (0, +inf].
void DemandLimit(double value, EnergyLimitUnit unit, const std::string& what,
                 const std::string& where) {
  TAUT_DEMAND(!std::isnan(value) && value > 0.0, where, ": ", what, " = ", value, " ",
              GetUnitName(unit), " is out of range; valid: (0, +inf] ",
              unit == EnergyLimitUnit::kEnergy ? "(energy per element)"
                                               : "(energy density, times the rest volume)",
              ", +inf = unlimited");
}

}  // namespace

EnergyLimitSettings EnergyLimitSettings::PerElementEnergy(double joules) {
  EnergyLimitSettings settings;
  settings.unit = EnergyLimitUnit::kEnergy;
  settings.u_max = joules;
  return settings;
}

EnergyLimitSettings EnergyLimitSettings::EnergyDensity(double density) {
  EnergyLimitSettings settings;
  settings.unit = EnergyLimitUnit::kEnergyDensity;
  settings.u_max = density;
  return settings;
}

void EnergyLimitSettings::Validate(int num_elements, const std::string& where) const {
  TAUT_DEMAND(unit == EnergyLimitUnit::kEnergy || unit == EnergyLimitUnit::kEnergyDensity, where,
              ": unknown energy limit unit ", static_cast<int>(unit),
              "; valid: kEnergy (J) or kEnergyDensity (J/m^3)");
  if (element_u_max.empty()) {
    DemandLimit(u_max, unit, "energy limit u_max", where);
  } else {
    TAUT_DEMAND(static_cast<int>(element_u_max.size()) == num_elements, where, ": ",
                element_u_max.size(), " per-element energy limits given for ", num_elements,
                " elements; give one per element or none");
    for (int e = 0; e < num_elements; ++e)
      DemandLimit(element_u_max[e], unit, internal::Concat("energy limit of element ", e), where);
  }
  TAUT_DEMAND(activation_margin >= 0.0, where, ": energy activation_margin = ", activation_margin,
              " is out of range; valid: [0, +inf]");
}

std::vector<double> CalcElementEnergyLimits(const EnergyLimitSettings& settings,
                                            const std::vector<double>& rest_volumes) {
  const int n = static_cast<int>(rest_volumes.size());
  std::vector<double> limits(n);
  for (int e = 0; e < n; ++e) {
    const double value =
        settings.element_u_max.empty() ? settings.u_max : settings.element_u_max[e];
    if (settings.unit == EnergyLimitUnit::kEnergy) {
      limits[e] = value;
    } else {
      TAUT_DEMAND(rest_volumes[e] > 0.0, "energy limits: rest volume of element ", e, " = ",
                  rest_volumes[e], " m^3; must be > 0 to convert an energy density");
      limits[e] = value * rest_volumes[e];  // U_max,e = u V_e
    }
  }
  return limits;
}

}  // namespace taut
