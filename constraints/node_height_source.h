// A floor under one deformable body as a source of SQP rows: every free node stays at or above a
// world height z_min (distance rows, C in m like contacts; docs/math.md §5.2-§5.3).
#pragma once

#include <vector>

#include "constraints/constraint_row.h"
#include "constraints/row_key_layouts.h"

namespace taut {

// Emits, for every free node i whose row value is below the activation margin at the iterate,
//   C_i = z_i - z_min >= 0,   z_i = e_z . x_i  (world z of node i at x [m]),
//   J_i = dC_i/dx_i = e_z     (on node i only; linear in x, so no curvature),
// a unilateral row of RowType::kNodeHeight. Fixed and kinematic nodes get no rows: their motion
// is prescribed, and a row on them could not be satisfied by the solve.
class NodeHeightSource final : public BodyConstraintSource {
 public:
  // Throws InputError naming the body for a z_min that is not finite, an activation margin that
  // is not positive and finite [m], or a source id beyond 2^16 - 1 (`source_id` makes row keys
  // unique among the sources of a world).
  NodeHeightSource(const DeformableBody& body, double z_min, double activation_margin,
                   int source_id);

  const DeformableBody& body() const override { return body_; }
  int AppendRows(const VecX& x, int body_index, std::vector<ConstraintRow>& rows) override;
  double CalcMaxViolation(const VecX& x) const override;
  double CalcViolationSum(const VecX& x) const override;

  double z_min() const { return z_min_; }                          // [m]
  double activation_margin() const { return activation_margin_; }  // [m]

 private:
  // C_i = z_i - z_min of node i at x [m].
  double CalcNodeHeight(const VecX& x, int i) const { return x[3 * i + 2] - z_min_; }

  const DeformableBody& body_;
  double z_min_;
  double activation_margin_;
  RowKeyPacker<1> key_;  // kNodeHeightRowKey with this source's id
};

}  // namespace taut
