// Energy limits of one deformable body as a source of SQP rows (paper B eq. 14;
// docs/math.md §4-§5).
#pragma once

#include <vector>

#include "constraints/constraint_row.h"
#include "constraints/energy_limit_rows.h"
#include "constraints/energy_limits.h"
#include "constraints/row_key_layouts.h"

namespace taut {

// Emits one row C = 1 - U_e/U_max,e per element whose C is below the activation margin, over the
// element's nodes with J = f_e/U_max (ElementModel::CalcElementForces: the element rotation
// frozen at x, docs/math.md §4.5; for tets the exact gradient).
class EnergyLimitSource final : public BodyConstraintSource {
 public:
  // The body's elements must have at most kMaxRowNodes nodes; settings are validated (throws
  // InputError naming the body).
  // `source_id` (< 2^16, else InputError) makes row keys unique among the sources of a world.
  EnergyLimitSource(const DeformableBody& body, const EnergyLimitSettings& settings, int source_id);

  const DeformableBody& body() const override { return body_; }
  int AppendRows(const VecX& x, int body_index, std::vector<ConstraintRow>& rows) override;
  double CalcMaxViolation(const VecX& x) const override;
  double CalcViolationSum(const VecX& x) const override;
  // Adds weights[c] K_e(R)/U_max,e (ElementModel::CalcElementStiffness, R frozen at the iterate;
  // energy_limit_rows.h) for each row of this source, the element decoded from the key.
  void AddIslandCurvature(const IslandIterate& iterate, const ConstraintRow* rows,
                          const double* weights, int count, CurvatureSink& sink) const override;

  const EnergyLimitSettings& settings() const { return settings_; }
  // U_max,e of every element [J] (energy densities already multiplied by the rest volume).
  const std::vector<double>& element_limits() const { return u_max_; }
  // max_e U_e / U_max,e at x (for reports; <= 1 when every limit holds).
  double CalcMaxEnergyRatio(const VecX& x) const;

 private:
  // U_e / U_max,e of element e at x (0 for an unlimited element).
  double CalcElementRatio(const VecX& x, int e) const;
  // True when element e's energy bound (ElementModel::CalcElementEnergyBound) at x is below
  // `fraction` U_max,e: then U_e < fraction U_max,e too, without the polar decomposition.
  bool IsSurelyBelow(const VecX& x, int e, double fraction) const;
  // U_e of element e at x (rotation recomputed from x) [J].
  double CalcElementEnergy(const VecX& x, int e) const;
  // Fills C, the element's nodes and J of the row of element e at x, R_e its rotation there.
  void FillRow(const VecX& x, int e, const Mat3& R, ConstraintRow& row) const;

  const DeformableBody& body_;
  EnergyLimitSettings settings_;
  std::vector<double> u_max_;  // U_max,e [J], +inf = unlimited
  RowKeyPacker<1> key_;        // kEnergyLimitRowKey with this source's id
  // R_e of the last AppendRows, at positions rows_x_: the curvature at the same x reuses them
  // (one polar decomposition per element and collection, not three per row).
  VecX rows_x_;
  std::vector<Mat3> rows_R_;
};

// The name of earlier releases, kept so that code written against them still compiles.
using EnergyLimitConstraint [[deprecated("renamed EnergyLimitSource")]] = EnergyLimitSource;

}  // namespace taut
