#include "constraints/energy_limit_constraint.h"

#include <algorithm>
#include <cmath>

#include "constraints/curvature_blocks.h"

namespace taut {

namespace {
// Throws unless the body is made of co-rotated tets or hexes.
void CheckElementType(const DeformableBody& body) {
  TAUT_DEMAND(dynamic_cast<const TetElementModel*>(&body.model()) != nullptr ||
                  dynamic_cast<const HexElementModel*>(&body.model()) != nullptr,
              "body '", body.name(),
              "': energy limits need a tet body (co-rotational tetrahedra) or a hex body "
              "(co-rotational hexahedra)");
}

// Rest volume of every element of the body [m^3], in element order.
std::vector<double> GatherRestVolumes(const ElementModel& model) {
  std::vector<double> volumes(model.num_elements());
  for (int e = 0; e < model.num_elements(); ++e) volumes[e] = model.element_rest_volume(e);
  return volumes;
}
}  // namespace

EnergyLimitConstraint::EnergyLimitConstraint(const DeformableBody& body,
                                             const EnergyLimitSettings& settings, int source_id)
    : body_(body),
      tets_((CheckElementType(body), dynamic_cast<const TetElementModel*>(&body.model()))),
      hexes_(dynamic_cast<const HexElementModel*>(&body.model())),
      settings_(settings),
      key_(kEnergyLimitRowKey, source_id) {
  settings_.Validate(body.model().num_elements(), "body '" + body.name() + "' energy limits");
  u_max_ = CalcElementEnergyLimits(settings_, GatherRestVolumes(body.model()));
}

double EnergyLimitConstraint::CalcElementEnergy(const VecX& x, int e) const {
  if (tets_ != nullptr)
    return CalcTetElementEnergy(tets_->rest().elements[e], tets_->lame(),
                                tets_->GatherElement(x, e));
  return CalcHexElementEnergy(hexes_->rest(e), hexes_->GatherElement(x, e),
                              hexes_->rotation_method());
}

void EnergyLimitConstraint::FillRow(const VecX& x, int e, ConstraintRow& row) const {
  const int* nodes = body_.model().element_nodes(e);
  if (tets_ != nullptr) {
    const TetEnergyLimitRow r = CalcTetEnergyLimitRow(tets_->rest().elements[e], tets_->lame(),
                                                      tets_->GatherElement(x, e), u_max_[e]);
    row.C = r.C;
    row.num_nodes = 4;
    for (int n = 0; n < 4; ++n) {
      row.nodes[n] = nodes[n];
      row.J[n] = r.J.segment<3>(3 * n);
    }
    return;
  }
  // Hex: R recomputed from x, then frozen for the Jacobian (docs/math.md §4.5).
  const HexRestElement& rest = hexes_->rest(e);
  const HexNodes xe = hexes_->GatherElement(x, e);
  const Mat3 R = CalcHexRotation(rest, xe, hexes_->rotation_method());
  const HexEnergyLimitRow r = CalcHexEnergyLimitRow(rest, xe, R, u_max_[e]);
  row.C = r.C;
  row.num_nodes = 8;
  for (int n = 0; n < 8; ++n) {
    row.nodes[n] = nodes[n];
    row.J[n] = r.J.segment<3>(3 * n);
  }
}

int EnergyLimitConstraint::AppendRows(const VecX& x, int body_index,
                                      std::vector<ConstraintRow>& rows) {
  const int before = static_cast<int>(rows.size());
  const double tau = settings_.activation_margin;
  for (int e = 0; e < body_.model().num_elements(); ++e) {
    if (std::isinf(u_max_[e])) continue;  // unlimited element: C = 1
    // Cheap energy test first; forces only for rows that are emitted.
    if (!(CalcEnergyLimitValue(CalcElementEnergy(x, e), u_max_[e]) < tau)) continue;
    ConstraintRow& row = rows.emplace_back();
    row.key = key_.Pack(e);  // one bound per element
    row.body = body_index;
    row.type = RowType::kEnergyLimit;
    FillRow(x, e, row);
  }
  return static_cast<int>(rows.size()) - before;
}

void EnergyLimitConstraint::AddIslandCurvature(const IslandIterate& iterate,
                                               const ConstraintRow* rows, const double* weights,
                                               int count, CurvatureSink& sink) const {
  for (int c = 0; c < count; ++c) {
    const ConstraintRow& row = rows[c];
    if (!key_.Owns(row.key) || !(weights[c] > 0.0)) continue;
    const int e = static_cast<int>(key_.Unpack(row.key)[0]);
    const VecX& x = iterate.x(row.body);
    const int* nodes = body_.model().element_nodes(e);
    if (tets_ != nullptr) {
      const Mat12 H = CalcTetEnergyLimitCurvature(tets_->rest().elements[e], tets_->lame(),
                                                  tets_->GatherElement(x, e), u_max_[e]);
      AddElementCurvatureBlocks<4>(H, weights[c], row.body, nodes, sink);
      continue;
    }
    const HexNodes xe = hexes_->GatherElement(x, e);
    const Mat3 R = CalcHexRotation(hexes_->rest(e), xe, hexes_->rotation_method());
    const Mat24 H = CalcHexEnergyLimitCurvature(hexes_->rest(e), R, u_max_[e]);
    AddElementCurvatureBlocks<8>(H, weights[c], row.body, nodes, sink);
  }
}

double EnergyLimitConstraint::CalcElementRatio(const VecX& x, int e) const {
  if (std::isinf(u_max_[e])) return 0.0;
  return CalcElementEnergy(x, e) / u_max_[e];
}

double EnergyLimitConstraint::CalcMaxViolation(const VecX& x) const {
  // max(0, -C) = max(0, U/U_max - 1).
  return std::max(0.0, CalcMaxEnergyRatio(x) - 1.0);
}

double EnergyLimitConstraint::CalcViolationSum(const VecX& x) const {
  double sum = 0.0;
  for (int e = 0; e < body_.model().num_elements(); ++e)
    sum += std::max(0.0, CalcElementRatio(x, e) - 1.0);
  return sum;
}

double EnergyLimitConstraint::CalcMaxEnergyRatio(const VecX& x) const {
  double ratio = 0.0;
  for (int e = 0; e < body_.model().num_elements(); ++e)
    ratio = std::max(ratio, CalcElementRatio(x, e));
  return ratio;
}

}  // namespace taut
