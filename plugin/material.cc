#include "plugin/material.h"

#include <cmath>

#include "plugin/common.h"

namespace taut {

double Material::lambda() const {
  return youngs_modulus * poisson_ratio / ((1.0 + poisson_ratio) * (1.0 - 2.0 * poisson_ratio));
}

double Material::mu() const { return youngs_modulus / (2.0 * (1.0 + poisson_ratio)); }

void Material::Validate(const std::string& where) const {
  TAUT_DEMAND(std::isfinite(youngs_modulus) && youngs_modulus > 0.0, where,
              ": Young's modulus must be finite and > 0 Pa, got ", youngs_modulus);
  TAUT_DEMAND(std::isfinite(poisson_ratio) && poisson_ratio > -1.0 && poisson_ratio < 0.5, where,
              ": Poisson's ratio must lie in (-1, 0.5), got ", poisson_ratio);
  TAUT_DEMAND(std::isfinite(density) && density > 0.0, where,
              ": density must be finite and > 0 kg/m^3, got ", density);
}

}  // namespace taut
