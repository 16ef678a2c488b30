// User-facing energy-limit settings of a body (paper B §4: U_e <= U_max per element) and their
// compiled per-element form. Element-type independent: tets and hexes share them.
//
// The limit is given either as an energy per element [J] or as an energy density [J/m^3] that is
// multiplied by each element's rest volume, U_max,e = u_max V_e. Either one value for the whole
// body or one value per element. +infinity means "this element is not limited".
#pragma once

#include <string>
#include <vector>

#include "plugin/common.h"

namespace taut {

// Unit of EnergyLimitSettings::u_max and element_u_max.
enum class EnergyLimitUnit {
  kEnergy,         // U_max per element [J] (paper B: "U_e <= 0.1 J")
  kEnergyDensity,  // energy density [J/m^3]; U_max,e = value * rest volume of element e
};

// Default activation margin tau: rows with C = 1 - U_e/U_max < tau are emitted, i.e. elements
// past 80 % of their energy limit.
constexpr double kDefaultEnergyActivationMargin = 0.2;

// Energy limits of one body. Build with PerElementEnergy() or EnergyDensity(), then Validate().
struct EnergyLimitSettings {
  EnergyLimitUnit unit = EnergyLimitUnit::kEnergy;
  // Body-wide limit in `unit`, in (0, +inf] (+inf: unlimited). Default 0 = not set (invalid).
  double u_max = 0.0;
  // Optional per-element limits in `unit`, one per element; when non-empty they replace u_max.
  std::vector<double> element_u_max;
  // Activation margin tau >= 0 (may be +inf): emit rows with C < tau (C = 1 at rest, 0 at the
  // limit).
  double activation_margin = kDefaultEnergyActivationMargin;

  // U_e <= joules for every element.
  static EnergyLimitSettings PerElementEnergy(double joules);
  // U_e <= density * V_e for every element (density in J/m^3, V_e the rest volume).
  static EnergyLimitSettings EnergyDensity(double density);

  // Throws InputError naming `where`, the quantity, the element and the valid range when the unit
  // is not an EnergyLimitUnit value, a limit is NaN or <= 0, the number of per-element limits
  // differs from num_elements, or the margin is NaN or negative.
  void Validate(int num_elements, const std::string& where) const;
};

// U_max,e [J] of every element from validated settings and the elements' rest volumes [m^3]
// (used only for kEnergyDensity). Throws InputError if a rest volume is not positive.
std::vector<double> CalcElementEnergyLimits(const EnergyLimitSettings& settings,
                                            const std::vector<double>& rest_volumes);

}  // namespace taut
