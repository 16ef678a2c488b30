// The rows of one island at an SQP iterate, shared by both island solvers (dual PGS and primal
// Newton): collection from the sources, the rows of each body, warm starts by row key.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "constraints/constraint_row.h"
#include "constraints/island_body.h"
#include "constraints/pgs_solver.h"
#include "constraints/step_stats.h"

namespace taut {

// Multipliers by row key, sorted by key (warm starts across SQP iterations and steps).
using KeyedMultipliers = std::vector<std::pair<std::uint64_t, double>>;

// True for rows whose C is a fraction of a limit (strain, energy); the others are distances [m].
inline bool IsLimitRow(const ConstraintRow& row) { return GetRowTypeInfo(row.type).is_limit; }
// Factor from the row's C to limit-row units: 1 for limit rows, distance_scale
// (SqpSettings::CalcDistanceScale) for distance rows.
inline double CalcLimitUnitScale(const ConstraintRow& row, double distance_scale) {
  return IsLimitRow(row) ? 1.0 : distance_scale;
}

class IslandRows {
 public:
  // Positions x_b of every body at velocities v, then the rows of every source there. Returns the
  // largest row violation in units of the limit rows' C: distance rows are scaled by
  // `distance_scale` (violation tolerance / contact tolerance).
  double Collect(double h, const std::vector<IslandBody*>& bodies,
                 const std::vector<ConstraintSource*>& sources, const std::vector<VecX>& v,
                 double distance_scale);
  // lambda (one per row) <- the multipliers of `from` with the same key, 0 for new rows.
  void WarmStart(const KeyedMultipliers& from, VecX& lambda) const;
  // to <- the nonzero multipliers of the rows by key, sorted.
  void Store(const VecX& lambda, KeyedMultipliers& to) const;
  // values[c] <- the value of `from` with row c's key where `from` has one; a strain row without
  // one takes an unclaimed value of a sibling key (same element and bound, another principal
  // direction: kStrainLimitDirectionBits); other rows keep theirs.
  void OverwriteByKey(const KeyedMultipliers& from, VecX& values) const;
  // Look-ahead rows (the dual path's rows found at a QP step): keeps the first `num_kept` rows,
  // then appends the limit rows of `from` (collected at velocities v_from) that have no row of
  // their group among them (a strain row's group is its element; any other row's, its key) and that
  // `from` violates or whose key is in `sticky` (sorted), linearized about this set's
  // velocities v: C <- C + h J (v - v_from), their first-order value here. Returns the number of
  // rows appended.
  int SetLookAheadRows(const IslandRows& from, int num_kept,
                       const std::vector<std::uint64_t>& sticky, double h,
                       const std::vector<VecX>& v, const std::vector<VecX>& v_from);
  // pgs <- the PGS rows of these rows (both PGS users: the dual path's QPs, frozen islands):
  // unilateral, bilateral with bounds, friction pairs on the Coulomb disk of their normal row.
  void CalcPgsRows(std::vector<PgsRow>& pgs) const;
  // Row counts by type into stats (rows_strain, ...).
  void CountTypes(StepStats& stats) const;
  // J v of a row for per-body velocities v.
  double CalcRowVelocity(int c, const std::vector<VecX>& v) const;
  // v_b += P_b^-1 (J^T lambda)_b for every body, P_b the factor body b holds
  // (IslandBody::SolveSystemApproximately): the velocity change the impulses lambda (one per row)
  // give, for start candidates. `work` is per-body scratch.
  void AddImpulseVelocities(const std::vector<IslandBody*>& bodies, const VecX& lambda,
                            std::vector<VecX>& work, std::vector<VecX>& v) const;

  int size() const { return static_cast<int>(rows_.size()); }
  bool empty() const { return rows_.empty(); }
  const ConstraintRow& operator[](int c) const { return rows_[c]; }
  const std::vector<ConstraintRow>& rows() const { return rows_; }
  // Rows touching body b (either side).
  const std::vector<int>& body_rows(int b) const { return body_rows_[b]; }
  // Positions of body b at the collected iterate.
  const VecX& x(int b) const { return x_[b]; }
  const std::vector<VecX>& positions() const { return x_; }

 private:
  std::vector<ConstraintRow> rows_;
  std::vector<std::vector<int>> body_rows_;
  std::vector<VecX> x_;
  mutable std::vector<char> claimed_;       // OverwriteByKey: entries of `from` taken
  mutable std::vector<int> unmatched_;      // OverwriteByKey: strain rows without their key
  std::vector<std::uint64_t> sorted_keys_;  // SetLookAheadRows: the kept rows' keys
};

}  // namespace taut
