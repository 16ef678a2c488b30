// Energy limits of one tet body as a source of SQP rows (paper B eq. 14; MATH.md §4-§5).
#pragma once

#include <vector>

#include "constraints/constraint_row.h"
#include "constraints/energy_limit_rows.h"
#include "constraints/energy_limits.h"
#include "plugin/tet_element_model.h"

namespace taut {

// Emits one row C = 1 - U_e/U_max,e per tet whose C is below the activation margin.
// A hex version only changes the element kernels (energy and forces) in the private helpers.
class EnergyLimitConstraint final : public ConstraintSource {
 public:
  // `body` must be a tet body; settings are validated (throws InputError naming the body).
  // `source_id` (< 2^16) makes row keys unique among the sources of a world.
  EnergyLimitConstraint(const DeformableBody& body, const EnergyLimitSettings& settings,
                        int source_id);

  const DeformableBody& body() const override { return body_; }
  int AppendRows(const VecX& x, int body_index, std::vector<ConstraintRow>& rows) override;
  double CalcMaxViolation(const VecX& x) const override;
  double CalcViolationSum(const VecX& x) const override;

  const EnergyLimitSettings& settings() const { return settings_; }
  // U_max,e of every element [J] (energy densities already multiplied by the rest volume).
  const std::vector<double>& element_limits() const { return u_max_; }
  // max_e U_e / U_max,e at x (for reports; <= 1 when every limit holds).
  double CalcMaxEnergyRatio(const VecX& x) const;

 private:
  // U_e / U_max,e of element e at x (0 for an unlimited element).
  double CalcElementRatio(const VecX& x, int e) const;

  const DeformableBody& body_;
  const TetElementModel& tets_;
  EnergyLimitSettings settings_;
  std::vector<double> u_max_;  // U_max,e [J], +inf = unlimited
  std::uint64_t key_prefix_;
};

}  // namespace taut
