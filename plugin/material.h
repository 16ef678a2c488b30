// Isotropic linear elastic material with density (SI units).
#pragma once

#include <string>

namespace taut {

// Linear isotropic material used by the co-rotational elements.
struct Material {
  double youngs_modulus = 1e5;  // E [Pa], > 0.
  double poisson_ratio = 0.3;   // nu [-], in (-1, 0.5).
  double density = 1000.0;      // rho [kg/m^3], > 0.

  // Lame's first parameter lambda = E nu / ((1 + nu)(1 - 2 nu)) [Pa].
  double lambda() const;
  // Shear modulus mu = E / (2 (1 + nu)) [Pa].
  double mu() const;
  // Throws InputError naming `where` and the offending quantity when out of range.
  void Validate(const std::string& where) const;
};

}  // namespace taut
