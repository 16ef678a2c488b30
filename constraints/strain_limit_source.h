// Strain limits of one tet body as a source of SQP rows (paper A; docs/math.md §2-§3).
#pragma once

#include <array>
#include <cmath>

#include "constraints/constraint_row.h"
#include "constraints/row_key_layouts.h"
#include "constraints/strain_limit_rows.h"
#include "plugin/tet_element_model.h"

namespace taut {

// Emits the strain-limit rows of every tet of a body whose C is below the activation margin.
class StrainLimitSource final : public BodyConstraintSource {
 public:
  // `body` must be a tet body; settings are validated (throws InputError naming the body).
  // `source_id` (< 2^16, else InputError) makes row keys unique among the sources of a world.
  StrainLimitSource(const DeformableBody& body, const StrainLimitSettings& settings, int source_id);

  const DeformableBody& body() const override { return body_; }
  int AppendRows(const VecX& x, int body_index, std::vector<ConstraintRow>& rows) override;
  double CalcMaxViolation(const VecX& x) const override;
  double CalcViolationSum(const VecX& x) const override;
  // Adds weights[c] [-d^2 C_c/dx^2]_+ of the rows of this source (element and row decoded from
  // the key) at the iterate: the s_i curvature of constraints/strain_limit_curvature.h.
  void AddIslandCurvature(const IslandIterate& iterate, const ConstraintRow* rows,
                          const double* weights, int count, CurvatureSink& sink) const override;

  const StrainLimitSettings& settings() const { return settings_; }
  // The compiled limits (params().projection is the evaluated rule).
  const StrainLimitParams& params() const { return params_; }
  // Strain |G q_j| - 1 along limit axis j of every element at x (for reports), largest value.
  double CalcMaxAxisStrain(const VecX& x, int axis) const;

 private:
  // Largest violation of element e at x.
  double CalcElementViolation(const VecX& x, int e) const;
  // Principal stretches strictly inside (lo, hi) give every row of an element C > tau.
  struct StretchBand {
    double lo = 0.0;
    double hi = HUGE_VAL;
  };
  // The band of activation margin tau (hyperbolic and ellipsoid modes, floor included).
  StretchBand CalcStretchBand(double tau) const;
  // True when every principal stretch of element e (positions xe) lies inside `band`, tested
  // exactly on F^T F without an SVD: then no row of the element has C below the band's tau.
  bool IsSurelyInside(const std::array<Vec3, 4>& xe, int e, const StretchBand& band) const;

  // The SVD of element e at positions xe, kept for the curvature at the same positions.
  const SignedSvd& RememberSvd(int e, const TetPositions& xe, const SignedSvd& svd);
  // The kept SVD of element e when it was taken at xe, else a fresh one.
  SignedSvd FindOrCalcSvd(int e, const TetPositions& xe) const;

  // The SVD of each element at the positions of the last AppendRows.
  struct CachedSvd {
    TetPositions x;
    SignedSvd svd;
    bool valid = false;
  };
  std::vector<CachedSvd> svd_cache_;

  const DeformableBody& body_;
  const TetElementModel& tets_;
  StrainLimitSettings settings_;
  StrainLimitParams params_;
  RowKeyPacker<4> key_;                       // kStrainLimitRowKey with this source's id
  std::vector<StrainLimitRow> element_rows_;  // scratch, reused
  bool full_curvature_ = false;   // HasStrainFrameCurvature(params_): rows' full_curvature
  bool exact_curvature_ = false;  // HasExactStrainCurvature(params_): rows' exact_curvature
  bool screen_ = false;           // IsSurelyInside applies (hyperbolic and ellipsoid modes)
  StretchBand active_band_;       // no row: C > activation margin
  StretchBand violation_band_;    // no violation: C > 0
};

// The name of earlier releases, kept so that code written against them still compiles.
using StrainLimitConstraint [[deprecated("renamed StrainLimitSource")]] = StrainLimitSource;

}  // namespace taut
