#include "constraints/strain_limit_constraint.h"

#include <algorithm>

namespace taut {

namespace {
const TetElementModel& AsTets(const DeformableBody& body) {
  const auto* tets = dynamic_cast<const TetElementModel*>(&body.model());
  TAUT_DEMAND(tets != nullptr, "body '", body.name(),
              "': strain limits need a tet body (co-rotational tetrahedra)");
  return *tets;
}
}  // namespace

StrainLimitConstraint::StrainLimitConstraint(const DeformableBody& body,
                                             const StrainLimitSettings& settings, int source_id)
    : body_(body), tets_(AsTets(body)), settings_(settings) {
  settings_.Validate(tets_.num_elements(), "body '" + body.name() + "' strain limits");
  TAUT_DEMAND(source_id >= 0 && source_id < (1 << 16), "strain limits: source id ", source_id,
              " out of range");
  params_ = CalcStrainLimitParams(settings_);
  key_prefix_ = static_cast<std::uint64_t>(source_id) << 48;
}

int StrainLimitConstraint::AppendRows(const VecX& x, int body_index,
                                      std::vector<ConstraintRow>& rows) {
  const int before = static_cast<int>(rows.size());
  for (int e = 0; e < tets_.num_elements(); ++e) {
    element_rows_.clear();
    const auto xe = tets_.GatherElement(x, e);
    if (AppendStrainLimitRows(e, tets_.rest().elements[e].r, xe,
                              SelectStrainLimitFrame(settings_, e), params_, &element_rows_) == 0)
      continue;
    const int* nodes = tets_.element_nodes(e);
    for (const StrainLimitRow& r : element_rows_) {
      ConstraintRow& row = rows.emplace_back();
      row.key = key_prefix_ | r.key.Pack();
      row.C = r.C;
      row.body = body_index;
      row.type = RowType::kStrainLimit;
      row.num_nodes = 4;
      for (int n = 0; n < 4; ++n) {
        row.nodes[n] = nodes[n];
        row.J[n] = r.J.segment<3>(3 * n);
      }
    }
  }
  return static_cast<int>(rows.size()) - before;
}

double StrainLimitConstraint::CalcElementViolation(const VecX& x, int e) const {
  return CalcStrainLimitViolation(tets_.rest().elements[e].r, tets_.GatherElement(x, e),
                                  SelectStrainLimitFrame(settings_, e), params_);
}

double StrainLimitConstraint::CalcMaxViolation(const VecX& x) const {
  double violation = 0.0;
  for (int e = 0; e < tets_.num_elements(); ++e)
    violation = std::max(violation, CalcElementViolation(x, e));
  return violation;
}

double StrainLimitConstraint::CalcViolationSum(const VecX& x) const {
  double sum = 0.0;
  for (int e = 0; e < tets_.num_elements(); ++e) sum += CalcElementViolation(x, e);
  return sum;
}

double StrainLimitConstraint::CalcMaxAxisStrain(const VecX& x, int axis) const {
  double strain = -1.0;
  for (int e = 0; e < tets_.num_elements(); ++e) {
    const Vec3 q = SelectStrainLimitFrame(settings_, e).col(axis);
    strain = std::max(strain, CalcMaterialAxisStrain(tets_.rest().elements[e].r,
                                                     tets_.GatherElement(x, e), q));
  }
  return strain;
}

}  // namespace taut
