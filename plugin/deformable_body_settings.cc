#include "plugin/deformable_body_settings.h"

#include <cmath>

#include "plugin/common.h"

namespace taut {

void DeformableBodySettings::Validate() const {
  material.Validate("body '" + name + "'");
  TAUT_DEMAND(std::isfinite(mass_damping) && mass_damping >= 0.0, "body '", name,
              "': mass damping (Rayleigh alpha) must be finite and >= 0 1/s, got ", mass_damping);
  TAUT_DEMAND(std::isfinite(stiffness_damping) && stiffness_damping >= 0.0, "body '", name,
              "': stiffness damping (Rayleigh beta) must be finite and >= 0 s, got ",
              stiffness_damping);
  TAUT_DEMAND(std::isfinite(friction) && friction >= 0.0, "body '", name,
              "': friction must be finite and >= 0, got ", friction);
  TAUT_DEMAND(std::isfinite(contact_margin) && contact_margin > 0.0, "body '", name,
              "': contact margin must be finite and > 0 m, got ", contact_margin);
  TAUT_DEMAND(restitution >= 0.0 && restitution <= 1.0, "body '", name,
              "': restitution must be in [0, 1], got ", restitution);
  TAUT_DEMAND(!std::isnan(max_speed) && max_speed > 0.0, "body '", name,
              "': max speed must be > 0 m/s (+inf disables the check), got ", max_speed);
  TAUT_DEMAND(std::isfinite(factor_reuse.min_refactor_cost) && factor_reuse.min_refactor_cost > 0.0,
              "body '", name, "': factor_reuse.min_refactor_cost must be finite and > 0, got ",
              factor_reuse.min_refactor_cost);
  TAUT_DEMAND(factor_reuse.pcg_tolerance > 0.0 && factor_reuse.pcg_tolerance < 1.0, "body '", name,
              "': factor_reuse.pcg_tolerance must be in (0, 1), got ", factor_reuse.pcg_tolerance);
}

}  // namespace taut
