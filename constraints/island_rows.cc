#include "constraints/island_rows.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "constraints/row_key_layouts.h"

namespace taut {

double IslandRows::Collect(double h, const std::vector<IslandBody*>& bodies,
                           const std::vector<ConstraintSource*>& sources,
                           const std::vector<VecX>& v, double distance_scale) {
  rows_.clear();
  x_.resize(bodies.size());
  for (size_t b = 0; b < bodies.size(); ++b) bodies[b]->CalcPositions(h, v[b], x_[b]);
  const IslandIterate iterate(h, bodies, v, x_);
  for (ConstraintSource* source : sources) source->AppendIslandRows(iterate, rows_);
  double violation = 0.0;
  for (const ConstraintRow& row : rows_)
    violation = std::max(violation, row.violation() * CalcLimitUnitScale(row, distance_scale));
  body_rows_.resize(bodies.size());
  for (auto& rows : body_rows_) rows.clear();
  for (size_t c = 0; c < rows_.size(); ++c) {
    body_rows_[rows_[c].body].push_back(static_cast<int>(c));
    if (rows_[c].body2 >= 0 && rows_[c].body2 != rows_[c].body)
      body_rows_[rows_[c].body2].push_back(static_cast<int>(c));
  }
  return violation;
}

void IslandRows::WarmStart(const KeyedMultipliers& from, VecX& lambda) const {
  lambda.setZero(size());
  OverwriteByKey(from, lambda);
}

namespace {
// Same element and bound, and the same limit axis j, except that the rows with one row per
// principal stretch (ellipsoid, linear interpolation: j = m) match each other whatever m is.
// Rows of different j (hyperbolic, orthogonal) are different constraints.
bool IsStrainRowSibling(std::uint64_t a, std::uint64_t b) {
  if ((a & ~kStrainLimitDirectionBits) != (b & ~kStrainLimitDirectionBits)) return false;
  const auto fields_a = UnpackRowKeyPayload(kStrainLimitRowKey, RowKeyPayload(a));
  const auto fields_b = UnpackRowKeyPayload(kStrainLimitRowKey, RowKeyPayload(b));
  const bool per_stretch_a = fields_a[1] == fields_a[2], per_stretch_b = fields_b[1] == fields_b[2];
  return per_stretch_a && per_stretch_b
             ? true
             : !per_stretch_a && !per_stretch_b && fields_a[1] == fields_b[1];
}
}  // namespace

void IslandRows::OverwriteByKey(const KeyedMultipliers& from, VecX& values) const {
  claimed_.assign(from.size(), 0);
  unmatched_.clear();
  for (size_t c = 0; c < rows_.size(); ++c) {
    const auto it =
        std::lower_bound(from.begin(), from.end(), std::make_pair(rows_[c].key, -HUGE_VAL));
    if (it != from.end() && it->first == rows_[c].key) {
      values[c] = it->second;
      claimed_[it - from.begin()] = 1;
    } else if (rows_[c].type == RowType::kStrainLimit) {
      unmatched_.push_back(static_cast<int>(c));
    }
  }
  // R3: the keys of one element are adjacent in `from` (the element field lies above the
  // direction and bound bits); take the first unclaimed one with the same bound.
  for (int c : unmatched_) {
    const std::uint64_t key = rows_[c].key;
    const std::uint64_t element = key >> kStrainLimitElementShift;
    const std::uint64_t first = element << kStrainLimitElementShift;
    for (auto it = std::lower_bound(from.begin(), from.end(), std::make_pair(first, -HUGE_VAL));
         it != from.end() && (it->first >> kStrainLimitElementShift) == element; ++it) {
      if (claimed_[it - from.begin()] || !IsStrainRowSibling(key, it->first)) continue;
      values[c] = it->second;
      claimed_[it - from.begin()] = 1;
      break;
    }
  }
}

namespace {
// A look-ahead row joins only where the kept rows have nothing of its group: the strain rows of
// one element form one group (whichever principal direction and bound: a sibling row linearized
// at another point would only compete with the kept one), every other row is its own.
std::uint64_t CalcLookAheadGroup(const ConstraintRow& row) {
  if (row.type != RowType::kStrainLimit) return row.key;
  return row.key >> kStrainLimitElementShift << kStrainLimitElementShift;
}
}  // namespace

int IslandRows::SetLookAheadRows(const IslandRows& from, int num_kept,
                                 const std::vector<std::uint64_t>& sticky, double h,
                                 const std::vector<VecX>& v, const std::vector<VecX>& v_from) {
  rows_.resize(num_kept);
  for (std::vector<int>& rows : body_rows_)
    while (!rows.empty() && rows.back() >= num_kept) rows.pop_back();
  sorted_keys_.clear();
  for (const ConstraintRow& row : rows_) sorted_keys_.push_back(CalcLookAheadGroup(row));
  std::sort(sorted_keys_.begin(), sorted_keys_.end());
  for (int c = 0; c < from.size(); ++c) {
    const ConstraintRow& row = from[c];
    // Limit rows only: contacts are collected within a margin before they touch, limit rows only
    // within their activation margin, which one step of v* can cross.
    if (!IsLimitRow(row) ||
        std::binary_search(sorted_keys_.begin(), sorted_keys_.end(), CalcLookAheadGroup(row)) ||
        !(row.violation() > 0.0 || std::binary_search(sticky.begin(), sticky.end(), row.key)))
      continue;
    const int r = size();
    ConstraintRow& added = rows_.emplace_back(row);
    // C(x) ~ C(x_from) + J (x - x_from), x - x_from = h (v - v_from).
    added.C += h * (from.CalcRowVelocity(c, v) - from.CalcRowVelocity(c, v_from));
    body_rows_[added.body].push_back(r);
    if (added.body2 >= 0 && added.body2 != added.body) body_rows_[added.body2].push_back(r);
  }
  return size() - num_kept;
}

void IslandRows::CalcPgsRows(std::vector<PgsRow>& pgs) const {
  pgs.assign(rows_.size(), MakeUnilateralRow());
  for (int c = 0; c < size(); ++c) {
    const ConstraintRow& row = rows_[c];
    if (row.bilateral) pgs[c] = MakeBilateralRow(row.lo, row.hi);
    if (row.friction_of == 0) continue;
    // A friction pair on the Coulomb disk of its contact's normal row c - friction_of.
    PgsRow& p = pgs[c];
    p.kind = RowKind::kFriction;
    p.cone = FrictionCone::kDisk;
    p.normal = c - row.friction_of;
    p.partner = row.friction_of == 1 ? c + 1 : c - 1;
    p.lo = -std::numeric_limits<double>::infinity();
    p.mu = row.mu;
  }
}

void IslandRows::Store(const VecX& lambda, KeyedMultipliers& to) const {
  to.clear();
  for (size_t c = 0; c < rows_.size(); ++c)
    if (lambda[c] != 0.0) to.emplace_back(rows_[c].key, lambda[c]);
  std::sort(to.begin(), to.end());
}

void IslandRows::CountTypes(StepStats& stats) const {
  auto count = [this](RowType type) {
    return static_cast<int>(std::count_if(rows_.begin(), rows_.end(),
                                          [type](const auto& r) { return r.type == type; }));
  };
  for (const RowTypeInfo& info : kRowTypes) stats.rows_of(info.type) = count(info.type);
}

double IslandRows::CalcRowVelocity(int c, const std::vector<VecX>& v) const {
  double jv = 0.0;
  rows_[c].ForEachEntry(
      [&](int body, int block, const Vec3& J) { jv += J.dot(v[body].segment<3>(3 * block)); });
  return jv;
}

void IslandRows::AddImpulseVelocities(const std::vector<IslandBody*>& bodies, const VecX& lambda,
                                      std::vector<VecX>& work, std::vector<VecX>& v) const {
  work.resize(bodies.size());
  for (size_t b = 0; b < bodies.size(); ++b) work[b].setZero(v[b].size());
  for (int c = 0; c < size(); ++c)
    rows_[c].ForEachEntry([&](int body, int block, const Vec3& J) {
      work[body].segment<3>(3 * block) += lambda[c] * J;
    });
  for (size_t b = 0; b < bodies.size(); ++b) {
    bodies[b]->SolveSystemApproximately(work[b]);
    v[b] += work[b];
  }
}

}  // namespace taut
