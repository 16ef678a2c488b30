#include "constraints/node_height_source.h"

#include <algorithm>
#include <cmath>

namespace taut {

NodeHeightSource::NodeHeightSource(const DeformableBody& body, double z_min,
                                   double activation_margin, int source_id)
    : body_(body),
      z_min_(z_min),
      activation_margin_(activation_margin),
      key_(kNodeHeightRowKey, source_id) {
  TAUT_DEMAND(std::isfinite(z_min), "body '", body.name(),
              "': node height limit: z_min must be finite, got ", z_min);
  TAUT_DEMAND(std::isfinite(activation_margin) && activation_margin > 0.0, "body '", body.name(),
              "': node height limit: activation margin must be positive and finite, got ",
              activation_margin, " m");
}

int NodeHeightSource::AppendRows(const VecX& x, int body_index, std::vector<ConstraintRow>& rows) {
  const int before = static_cast<int>(rows.size());
  for (int i = 0; i < body_.num_nodes(); ++i) {
    if (body_.node_kind(i) != NodeKind::kFree) continue;
    // Rows within the margin only (docs/math.md §5.5: like contacts, gap < margin).
    const double C = CalcNodeHeight(x, i);
    if (!(C < activation_margin_)) continue;
    ConstraintRow& row = rows.emplace_back();
    row.key = key_.Pack(i);  // one row per node
    row.C = C;               // [m], a distance row (docs/math.md §5.2)
    row.type = RowType::kNodeHeight;
    row.body = body_index;
    row.num_nodes = 1;
    row.nodes[0] = i;
    row.J[0] = Vec3::UnitZ();  // dC/dx_i = e_z, exact (C linear in x)
  }
  return static_cast<int>(rows.size()) - before;
}

double NodeHeightSource::CalcMaxViolation(const VecX& x) const {
  double violation = 0.0;
  for (int i = 0; i < body_.num_nodes(); ++i)
    if (body_.node_kind(i) == NodeKind::kFree)
      violation = std::max(violation, -CalcNodeHeight(x, i));
  return violation;
}

double NodeHeightSource::CalcViolationSum(const VecX& x) const {
  double sum = 0.0;
  for (int i = 0; i < body_.num_nodes(); ++i)
    if (body_.node_kind(i) == NodeKind::kFree) sum += std::max(0.0, -CalcNodeHeight(x, i));
  return sum;
}

}  // namespace taut
