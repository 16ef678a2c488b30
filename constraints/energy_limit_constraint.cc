#include "constraints/energy_limit_constraint.h"

#include <algorithm>
#include <cmath>

namespace taut {

namespace {
const TetElementModel& AsTets(const DeformableBody& body) {
  const auto* tets = dynamic_cast<const TetElementModel*>(&body.model());
  TAUT_DEMAND(tets != nullptr, "body '", body.name(),
              "': energy limits need a tet body (co-rotational tetrahedra); hex bodies are not "
              "supported yet");
  return *tets;
}

// Rest volume of every tet of the body [m^3].
std::vector<double> GatherRestVolumes(const TetElementModel& tets) {
  std::vector<double> volumes(tets.num_elements());
  for (int e = 0; e < tets.num_elements(); ++e) volumes[e] = tets.rest().elements[e].volume;
  return volumes;
}
}  // namespace

EnergyLimitConstraint::EnergyLimitConstraint(const DeformableBody& body,
                                             const EnergyLimitSettings& settings, int source_id)
    : body_(body), tets_(AsTets(body)), settings_(settings) {
  settings_.Validate(tets_.num_elements(), "body '" + body.name() + "' energy limits");
  TAUT_DEMAND(source_id >= 0 && source_id < (1 << 16), "energy limits: source id ", source_id,
              " out of range");
  u_max_ = CalcElementEnergyLimits(settings_, GatherRestVolumes(tets_));
  key_prefix_ = static_cast<std::uint64_t>(source_id) << 48;
}

int EnergyLimitConstraint::AppendRows(const VecX& x, int body_index,
                                      std::vector<ConstraintRow>& rows) {
  const int before = static_cast<int>(rows.size());
  const double tau = settings_.activation_margin;
  for (int e = 0; e < tets_.num_elements(); ++e) {
    if (std::isinf(u_max_[e])) continue;  // unlimited element: C = 1
    const TetRestElement& rest = tets_.rest().elements[e];
    const auto xe = tets_.GatherElement(x, e);
    // Cheap energy test first; forces only for rows that are emitted.
    if (!(CalcEnergyLimitValue(CalcTetElementEnergy(rest, tets_.lame(), xe), u_max_[e]) < tau))
      continue;
    const TetEnergyLimitRow r = CalcTetEnergyLimitRow(rest, tets_.lame(), xe, u_max_[e]);
    const int* nodes = tets_.element_nodes(e);
    ConstraintRow& row = rows.emplace_back();
    row.key = key_prefix_ | static_cast<std::uint64_t>(e);  // one bound per element
    row.C = r.C;
    row.body = body_index;
    row.type = RowType::kEnergyLimit;
    row.num_nodes = 4;
    for (int n = 0; n < 4; ++n) {
      row.nodes[n] = nodes[n];
      row.J[n] = r.J.segment<3>(3 * n);
    }
  }
  return static_cast<int>(rows.size()) - before;
}

double EnergyLimitConstraint::CalcElementRatio(const VecX& x, int e) const {
  if (std::isinf(u_max_[e])) return 0.0;
  return CalcTetElementEnergy(tets_.rest().elements[e], tets_.lame(), tets_.GatherElement(x, e)) /
         u_max_[e];
}

double EnergyLimitConstraint::CalcMaxViolation(const VecX& x) const {
  // max(0, -C) = max(0, U/U_max - 1).
  return std::max(0.0, CalcMaxEnergyRatio(x) - 1.0);
}

double EnergyLimitConstraint::CalcViolationSum(const VecX& x) const {
  double sum = 0.0;
  for (int e = 0; e < tets_.num_elements(); ++e) sum += std::max(0.0, CalcElementRatio(x, e) - 1.0);
  return sum;
}

double EnergyLimitConstraint::CalcMaxEnergyRatio(const VecX& x) const {
  double ratio = 0.0;
  for (int e = 0; e < tets_.num_elements(); ++e) ratio = std::max(ratio, CalcElementRatio(x, e));
  return ratio;
}

}  // namespace taut
