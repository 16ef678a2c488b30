#include "constraints/strain_limits.h"

#include <Eigen/LU>
#include <cmath>

namespace taut {
namespace {

// Tolerance on ||Q^T Q - I||_F for a limit frame to count as a rotation.
constexpr double kRotationTolerance = 1e-6;

// Throws InputError unless Q is a finite proper rotation.
void DemandRotation(const Mat3& Q, const std::string& what, const std::string& where) {
  TAUT_DEMAND(Q.allFinite(), where, ": ", what, " has a non-finite entry; it must be a rotation");
  const double orth = (Q.transpose() * Q - Mat3::Identity()).norm();
  const double det = Q.determinant();
  TAUT_DEMAND(orth <= kRotationTolerance && det > 0.0, where, ": ", what,
              " is not a rotation (|Q^T Q - I| = ", orth, ", det Q = ", det,
              "); its columns must be orthonormal limit axes with det Q = +1");
}

// 1/|s - 1| for a limited axis, 0 for an unlimited one (docs/math.md §3.1).
double CalcKappa(double s, bool limited) { return limited ? 1.0 / std::abs(s - 1.0) : 0.0; }

// True when the non-zero (limited) entries of kappa are all equal. Exact comparison: equal
// limits given as equal doubles give bit-equal kappas.
bool HasEqualLimitedEntries(const Vec3& kappa) {
  double value = 0.0;
  for (int j = 0; j < 3; ++j) {
    if (kappa[j] == 0.0) continue;
    if (value != 0.0 && kappa[j] != value) return false;
    value = kappa[j];
  }
  return true;
}

// The rows evaluated for the settings: hyperbolic with equal limits on every limited axis of
// both bounds becomes the ellipsoid rule (docs/math.md §3.7: identical for one limited
// axis, isotropy-consistent for more).
StrainProjection SelectEvaluatedProjection(const StrainLimitSettings& settings,
                                           const StrainLimitParams& params) {
  const bool equal =
      HasEqualLimitedEntries(params.kappa_min) && HasEqualLimitedEntries(params.kappa_max);
  if (settings.projection == StrainProjection::kHyperbolic && settings.equal_limits_use_ellipsoid &&
      equal)
    return StrainProjection::kEllipsoid;
  return settings.projection;
}

}  // namespace

StrainLimitSettings StrainLimitSettings::Isotropic(double s_min, double s_max,
                                                   StrainProjection projection) {
  return PerAxis(Vec3::Constant(s_min), Vec3::Constant(s_max), projection);
}

StrainLimitSettings StrainLimitSettings::PerAxis(const Vec3& s_min, const Vec3& s_max,
                                                 StrainProjection projection) {
  StrainLimitSettings settings;
  settings.s_min = s_min;
  settings.s_max = s_max;
  settings.projection = projection;
  return settings;
}

void StrainLimitSettings::Validate(int num_elements, const std::string& where) const {
  const int mode = static_cast<int>(projection);
  TAUT_DEMAND(mode >= static_cast<int>(StrainProjection::kHyperbolic) &&
                  mode <= static_cast<int>(StrainProjection::kEllipsoid),
              where, ": unknown strain projection ", mode,
              "; valid: kHyperbolic, kOrthogonal, kLinearInterpolation, kEllipsoid");
  for (int j = 0; j < 3; ++j) {
    const double lo = s_min[j];
    const double hi = s_max[j];
    TAUT_DEMAND(!std::isnan(lo), where, ": strain limit s_min[", j,
                "] is NaN; valid: 0 (unlimited) or a compress ratio in (0, 1)");
    TAUT_DEMAND(!std::isnan(hi), where, ": strain limit s_max[", j,
                "] is NaN; valid: +infinity (unlimited) or a stretch ratio in (1, +inf)");
    // Only a pair of plausible ratios (s_max > 1) is reported as inverted; otherwise the range
    // checks below name the bad value.
    TAUT_DEMAND(lo <= hi || hi <= 1.0, where, ": strain limits on axis ", j, " have s_min[", j,
                "] = ", lo, " > s_max[", j, "] = ", hi, "; valid: 0 <= s_min < 1 < s_max");
    TAUT_DEMAND(lo == 0.0 || (lo > 0.0 && lo < 1.0), where, ": strain limit s_min[", j, "] = ", lo,
                " is out of range; valid: 0 (unlimited) or a compress ratio in (0, 1)"
                " (1 would need kappa = 1/|s - 1| = inf)");
    TAUT_DEMAND(hi > 1.0, where, ": strain limit s_max[", j, "] = ", hi,
                " is out of range; valid: +infinity (unlimited) or a stretch ratio in (1, +inf)"
                " (0 does not mean unlimited; 1 would need kappa = inf)");
  }
  DemandRotation(frame, "strain-limit frame", where);
  if (!element_frames.empty()) {
    TAUT_DEMAND(static_cast<int>(element_frames.size()) == num_elements, where, ": ",
                element_frames.size(), " strain-limit element frames given for ", num_elements,
                " elements; give one per element or none");
    for (int e = 0; e < num_elements; ++e) {
      DemandRotation(element_frames[e], internal::Concat("strain-limit frame of element ", e),
                     where);
    }
  }
  TAUT_DEMAND(unlimited_s_min_cap >= 0.0 && unlimited_s_min_cap < 1.0, where,
              ": unlimited_s_min_cap = ", unlimited_s_min_cap, " is out of range; valid: [0, 1)");
  TAUT_DEMAND(std::isfinite(unlimited_s_max_cap) && unlimited_s_max_cap > 1.0, where,
              ": unlimited_s_max_cap = ", unlimited_s_max_cap,
              " is out of range; valid: finite and > 1");
  TAUT_DEMAND(activation_margin >= 0.0, where, ": strain activation_margin = ", activation_margin,
              " is out of range; valid: [0, +inf]");
  TAUT_DEMAND(std::isfinite(svd_gap_epsilon) && svd_gap_epsilon >= 0.0, where,
              ": svd_gap_epsilon = ", svd_gap_epsilon, " is out of range; valid: finite and >= 0");
  TAUT_DEMAND(hyperbolic_row_band >= 0.0, where, ": hyperbolic_row_band = ", hyperbolic_row_band,
              " is out of range; valid: [0, +inf]");
  TAUT_DEMAND(inversion_floor >= 0.0 && inversion_floor < 1.0, where,
              ": inversion_floor = ", inversion_floor, " is out of range; valid: [0, 1)");
}

StrainLimitParams CalcStrainLimitParams(const StrainLimitSettings& settings) {
  StrainLimitParams params;
  params.projection = settings.projection;
  for (int j = 0; j < 3; ++j) {
    const bool min_limited = settings.s_min[j] > 0.0;
    const bool max_limited = std::isfinite(settings.s_max[j]);
    params.kappa_min[j] = CalcKappa(settings.s_min[j], min_limited);
    params.kappa_max[j] = CalcKappa(settings.s_max[j], max_limited);
    params.d_min_capped[j] = (min_limited ? settings.s_min[j] : settings.unlimited_s_min_cap) - 1.0;
    params.d_max_capped[j] = (max_limited ? settings.s_max[j] : settings.unlimited_s_max_cap) - 1.0;
    params.has_min = params.has_min || min_limited;
    params.has_max = params.has_max || max_limited;
  }
  params.activation_margin = settings.activation_margin;
  params.svd_gap_epsilon = settings.svd_gap_epsilon;
  params.freeze_frame_jacobian = settings.freeze_frame_jacobian;
  params.full_frame_curvature = settings.full_frame_curvature;
  params.hyperbolic_row_band = settings.hyperbolic_row_band;
  // The floor guards limited elements only: a body without limits emits no rows at all.
  params.inversion_floor = params.has_min || params.has_max ? settings.inversion_floor : 0.0;
  params.projection = SelectEvaluatedProjection(settings, params);
  return params;
}

const Mat3& SelectStrainLimitFrame(const StrainLimitSettings& settings, int element) {
  if (settings.element_frames.empty()) return settings.frame;
  TAUT_ASSERT(element >= 0 && element < static_cast<int>(settings.element_frames.size()));
  return settings.element_frames[element];
}

const char* GetStrainProjectionName(StrainProjection projection) {
  switch (projection) {
    case StrainProjection::kHyperbolic:
      return "hyperbolic";
    case StrainProjection::kOrthogonal:
      return "orthogonal";
    case StrainProjection::kLinearInterpolation:
      return "linear_interpolation";
    case StrainProjection::kEllipsoid:
      return "ellipsoid";
  }
  return "unknown";
}

}  // namespace taut
