#include "constraints/energy_limit_source.h"

#include <algorithm>
#include <cmath>

namespace taut {

namespace {
// Rest volume of every element of the body [m^3], in element order.
std::vector<double> GatherRestVolumes(const ElementModel& model) {
  std::vector<double> volumes(model.num_elements());
  for (int e = 0; e < model.num_elements(); ++e) volumes[e] = model.element_rest_volume(e);
  return volumes;
}
}  // namespace

EnergyLimitSource::EnergyLimitSource(const DeformableBody& body,
                                     const EnergyLimitSettings& settings, int source_id)
    : body_(body), settings_(settings), key_(kEnergyLimitRowKey, source_id) {
  TAUT_DEMAND(body.model().nodes_per_element() <= kMaxRowNodes, "body '", body.name(),
              "': energy limits need elements of at most ", kMaxRowNodes, " nodes, got ",
              body.model().nodes_per_element());
  settings_.Validate(body.model().num_elements(), "body '" + body.name() + "' energy limits");
  u_max_ = CalcElementEnergyLimits(settings_, GatherRestVolumes(body.model()));
}

double EnergyLimitSource::CalcElementEnergy(const VecX& x, int e) const {
  return body_.model().CalcElementEnergy(e, x);
}

void EnergyLimitSource::FillRow(const VecX& x, int e, const Mat3& R, ConstraintRow& row) const {
  // R = R_e at x (computed once by AppendRows), frozen for the Jacobian J = f_e / U_max
  // (docs/math.md §4.5) and the curvature -d^2C/dx^2 = K_e(R) / U_max (AddIslandCurvature):
  // along J, J^T K_e J / U_max = f^T K_e f / U_max^3.
  const ElementModel& model = body_.model();
  ElementVectors forces;
  double f_K_f = 0.0;
  const double energy = model.CalcElementForcesAndStiffnessAlongIn(e, x, R, forces, &f_K_f);
  row.C = CalcEnergyLimitValue(energy, u_max_[e]);
  row.curvature_along_j = f_K_f / (u_max_[e] * u_max_[e] * u_max_[e]);
  row.num_nodes = model.nodes_per_element();
  CalcEnergyLimitJacobian(forces.data(), row.num_nodes, u_max_[e], row.J.data());
  const int* nodes = model.element_nodes(e);
  for (int n = 0; n < row.num_nodes; ++n) row.nodes[n] = nodes[n];
}

int EnergyLimitSource::AppendRows(const VecX& x, int body_index, std::vector<ConstraintRow>& rows) {
  const int before = static_cast<int>(rows.size());
  const double tau = settings_.activation_margin;
  const ElementModel& model = body_.model();
  rows_x_ = x;
  rows_R_.resize(model.num_elements());
  for (int e = 0; e < model.num_elements(); ++e) {
    if (std::isinf(u_max_[e])) continue;  // unlimited element: C = 1
    // A row needs C = 1 - U/U_max < tau: none where the bound already gives U < (1 - tau) U_max.
    if (IsSurelyBelow(x, e, 1.0 - tau)) continue;
    // Cheap energy test first; forces only for rows that are emitted.
    rows_R_[e] = model.CalcElementRotation(e, x);
    const double energy = model.CalcElementEnergyIn(e, x, rows_R_[e]);
    if (!(CalcEnergyLimitValue(energy, u_max_[e]) < tau)) continue;
    ConstraintRow& row = rows.emplace_back();
    row.key = key_.Pack(e);  // one bound per element
    row.body = body_index;
    row.element = e;
    row.type = RowType::kEnergyLimit;
    FillRow(x, e, rows_R_[e], row);
  }
  return static_cast<int>(rows.size()) - before;
}

void EnergyLimitSource::AddIslandCurvature(const IslandIterate& iterate, const ConstraintRow* rows,
                                           const double* weights, int count,
                                           CurvatureSink& sink) const {
  int rows_frame = -1;  // 1 when the iterate is at rows_x_ (tested once)
  for (int c = 0; c < count; ++c) {
    const ConstraintRow& row = rows[c];
    if (!key_.Owns(row.key) || !(weights[c] > 0.0)) continue;
    const int e = static_cast<int>(key_.Unpack(row.key)[0]);
    // -d^2 C/dx^2 = K_e(R)/U_max with R frozen at the iterate (the rows' R_e when they were
    // collected at the same positions).
    const VecX& x = iterate.x(row.body);  // this body's: the same for every row of the source
    if (rows_frame < 0) rows_frame = x.size() == rows_x_.size() && x == rows_x_;
    ElementMatrix H;
    body_.model().CalcElementStiffnessIn(
        e, rows_frame ? rows_R_[e] : body_.model().CalcElementRotation(e, x), H);
    H *= weights[c] / u_max_[e];
    sink.AddElementBlock(row.body, e, body_.model().element_nodes(e), H);
  }
}

bool EnergyLimitSource::IsSurelyBelow(const VecX& x, int e, double fraction) const {
  // The bound is loose by a factor of a few at small strains (docs/math.md §4.6); the margin
  // 1e-6 keeps rounding of the exact U from crossing it.
  return body_.model().CalcElementEnergyBound(e, x) * (1.0 + 1e-6) < fraction * u_max_[e];
}

double EnergyLimitSource::CalcElementRatio(const VecX& x, int e) const {
  if (std::isinf(u_max_[e])) return 0.0;
  return CalcElementEnergy(x, e) / u_max_[e];
}

double EnergyLimitSource::CalcMaxViolation(const VecX& x) const {
  // max(0, -C) = max(0, U/U_max - 1): 0 for the elements surely below their limit.
  double violation = 0.0;
  for (int e = 0; e < body_.model().num_elements(); ++e)
    if (!std::isinf(u_max_[e]) && !IsSurelyBelow(x, e, 1.0))
      violation = std::max(violation, CalcElementRatio(x, e) - 1.0);
  return violation;
}

double EnergyLimitSource::CalcViolationSum(const VecX& x) const {
  double sum = 0.0;
  for (int e = 0; e < body_.model().num_elements(); ++e)
    if (!std::isinf(u_max_[e]) && !IsSurelyBelow(x, e, 1.0))
      sum += std::max(0.0, CalcElementRatio(x, e) - 1.0);
  return sum;
}

double EnergyLimitSource::CalcMaxEnergyRatio(const VecX& x) const {
  double ratio = 0.0;
  for (int e = 0; e < body_.model().num_elements(); ++e)
    ratio = std::max(ratio, CalcElementRatio(x, e));
  return ratio;
}

}  // namespace taut
