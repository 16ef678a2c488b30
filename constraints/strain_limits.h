// User-facing strain-limit settings of a tet body (paper A §3; docs/math.md §2-§3) and their
// compiled, validated form used by the row evaluation (constraints/strain_limit_rows.h).
//
// Limits are given per material limit axis j = 0, 1, 2 as stretch ratios: s_min[j] <= s <= s_max[j]
// for the principal stretches s of the deformation gradient, projected onto axis j by the chosen
// StrainProjection. The limit axes are the columns q_j of a rotation Q in rest coordinates (the
// body frame, or one frame per element for fibre directions); with Q = I they are the world axes
// of the rest mesh. Internally the limits become kappa^j = 1/|s^j - 1| (kappa = 0: unlimited,
// docs/math.md §3.1), so no infinity reaches a formula.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "plugin/common.h"

namespace taut {

// How axis limits become limits along the principal directions v_i (V' = Q^T V, w = V' e_i).
enum class StrainProjection {
  kHyperbolic,           // paper A eqs. 7-8: s^{j,i} = 1 + d^j / |V'_ji|; 18 rows per tet.
  kOrthogonal,           // paper A eqs. 19-20: s^{j,i} = 1 + d^j |V'_ji|; freezes
                         // (docs/math.md §6 A1).
  kLinearInterpolation,  // paper A eqs. 21-22: s^i = ||diag(s^j) w||; 6 rows; needs caps.
  kEllipsoid,            // docs/math.md §3.5 (2-norm): d^i = 1 / ||K w||; isotropy-consistent.
                         // With equal limits on all axes this is paper A's isotropic limit
                         // (eqs. 9-10): s_min <= s_i <= s_max for every i, in any frame.
};

// Value of s_max[j] meaning "no stretch limit on this axis" (s_min[j] = 0 means no compress limit).
constexpr double kUnlimitedStretch = std::numeric_limits<double>::infinity();
// Default activation margin tau: rows with C < tau are emitted (C = 1 at rest, 0 at the limit).
constexpr double kDefaultStrainActivationMargin = 0.2;
// Default band of the hyperbolic row filter (StrainLimitSettings::hyperbolic_row_band) [C units].
constexpr double kDefaultHyperbolicRowBand = 0.05;
// Default non-inversion floor (StrainLimitSettings::inversion_floor) [-].
constexpr double kDefaultInversionFloor = 0.1;

// Strain limits of one body. Build with Isotropic() or PerAxis(), then Validate().
struct StrainLimitSettings {
  // Compress limit per material axis j [-]: in (0, 1), or 0 = unlimited. Default: unlimited.
  Vec3 s_min = Vec3::Zero();
  // Stretch limit per material axis j [-]: in (1, +inf), or kUnlimitedStretch. Default: unlimited.
  Vec3 s_max = Vec3::Constant(kUnlimitedStretch);
  // Projection of axis limits onto principal directions. Default: paper A's hyperbolic rule
  // (Isotropic() defaults to kEllipsoid, paper A's isotropic limit).
  StrainProjection projection = StrainProjection::kHyperbolic;
  // kHyperbolic only: when each bound's limits are equal on all of its limited axes, evaluate
  // the ellipsoid rows instead (docs/math.md §3.7): one row per principal axis and bound,
  // C = 1 - kappa |s_i - 1| ||P_L V' e_i|| (P_L: the limited axes). Identical to the hyperbolic
  // rows for one limited axis; for two or three equal axes it is the isotropy-consistent limit
  // (exactly d in every direction of the limited subspace) where the hyperbolic rule allows up
  // to sqrt(2) d or sqrt(3) d (docs/math.md §6 A3). false: paper A's rows. Default true.
  bool equal_limits_use_ellipsoid = true;
  // kHyperbolic only, >= 0 (may be +inf): per (principal axis i, bound) emit only the dominant
  // row (smallest C over the axes j) and the rows with C_j < C_min + band. The others satisfy
  // C_j >= C_min at the iterate, so the feasible set is unchanged (violations are always
  // measured over every row); +inf emits every row (paper A). Default 0.05.
  double hyperbolic_row_band = kDefaultHyperbolicRowBand;
  // Non-inversion floor s_floor in [0, 1) [-]: every principal stretch of a limited element stays
  // at or above it, s_i >= s_floor for i = 1..3, whatever the axis limits (docs/math.md §3.8).
  // Axis limits leave the unlimited directions free, and there a soft element can be crushed
  // through s_3 = 0 (inverted); at an inverted element the linearized axis rows can be locally
  // infeasible (a stationary point with the row still violated). Rows
  // C = (s_i - s_floor) / (1 - s_floor) >= 0, emitted within the activation margin like the
  // others. Where an axis' own compress limit is below the floor, the floor wins. 0 = no floor.
  // Default 0.1: no row appears until a principal stretch falls below 0.28.
  double inversion_floor = kDefaultInversionFloor;
  // Body limit frame Q: columns are the limit axes in rest coordinates; a rotation. Default I.
  Mat3 frame = Mat3::Identity();
  // Optional per-element frames (fibre directions), one rotation per tet; when non-empty they
  // replace `frame`. Default: empty.
  std::vector<Mat3> element_frames;
  // kOrthogonal / kLinearInterpolation only: s used for an unlimited compress axis, in [0, 1).
  // Default 0 (d = -1, docs/math.md §3.1). Results of these modes depend on the caps.
  double unlimited_s_min_cap = 0.0;
  // kOrthogonal / kLinearInterpolation only: s used for an unlimited stretch axis, finite, > 1.
  // Default 2 (d = 1, docs/math.md §3.1).
  double unlimited_s_max_cap = 2.0;
  // Activation margin tau >= 0 (may be +inf): emit rows with C < tau. C is the remaining fraction
  // of the limit (1 at rest, 0 at the limit), so tau = 0.2 emits rows past 80 % of their limit.
  double activation_margin = kDefaultStrainActivationMargin;
  // Gap clamp epsilon of docs/math.md §2 R1 [s^2 units], >= 0, finite. Default 1e-6: exact
  // derivatives except at near-repeated values (the SQP re-evaluates the rows at every iterate).
  double svd_gap_epsilon = 1e-6;
  // Use the frozen-frame Jacobian (dV/dx = 0), for comparison with the exact one. Default false.
  bool freeze_frame_jacobian = false;
  // Primal path's row curvature with the frame factor's second derivative (docs/math.md §5.9):
  // with the slack-push penalty growth the soft anisotropic beam needs 16 instead of 36 Newton
  // iterations per step and its step is 1.5x faster. false: the stretch term only (each row's
  // [+-d^2 s_i]_+). Default true.
  bool full_frame_curvature = true;

  // Paper A's isotropic limit (eqs. 9-10): s_min <= s_i <= s_max for every principal stretch
  // s_i, whatever the frame (0 / kUnlimitedStretch = unlimited). The default kEllipsoid rows
  // are then exactly C = 1 - kappa |s_i - 1|, one per principal stretch and bound; other
  // projections apply their own rule to the equal axis limits (kHyperbolic switches to the
  // ellipsoid rows unless equal_limits_use_ellipsoid is false).
  static StrainLimitSettings Isotropic(double s_min, double s_max,
                                       StrainProjection projection = StrainProjection::kEllipsoid);
  // Per-axis limits (paper A §3.2: s^j_min, s^j_max on material axis j).
  static StrainLimitSettings PerAxis(const Vec3& s_min, const Vec3& s_max,
                                     StrainProjection projection = StrainProjection::kHyperbolic);

  // Throws InputError naming `where`, the quantity, the axis or element and the valid range when a
  // limit is NaN or out of range, s_min > s_max, the projection is not a StrainProjection value, a
  // frame is not a rotation, the number of element frames differs from num_elements, or a cap /
  // margin / epsilon / band is out of range.
  void Validate(int num_elements, const std::string& where) const;
};

// Compiled limits of one body, as used by the row evaluation (docs/math.md §3).
struct StrainLimitParams {
  // The rows evaluated: settings.projection, or kEllipsoid for kHyperbolic with equal limits
  // (StrainLimitSettings::equal_limits_use_ellipsoid).
  StrainProjection projection = StrainProjection::kHyperbolic;
  Vec3 kappa_min = Vec3::Zero();     // kappa^j = 1/(1 - s_min[j]); 0 = unlimited
  Vec3 kappa_max = Vec3::Zero();     // kappa^j = 1/(s_max[j] - 1); 0 = unlimited
  Vec3 d_min_capped = Vec3::Zero();  // s_min[j] - 1, caps on unlimited axes (OP, LI), in [-1, 0)
  Vec3 d_max_capped = Vec3::Zero();  // s_max[j] - 1, caps on unlimited axes (OP, LI), > 0
  bool has_min = false;  // some axis has a compress limit (else no C_min rows in any mode)
  bool has_max = false;  // some axis has a stretch limit (else no C_max rows in any mode)
  double activation_margin = kDefaultStrainActivationMargin;  // tau
  double svd_gap_epsilon = 1e-6;                              // R1 epsilon
  bool freeze_frame_jacobian = false;                         // dV/dx := 0
  bool full_frame_curvature = true;                           // docs/math.md §5.9
  double hyperbolic_row_band = kDefaultHyperbolicRowBand;     // emit C_j <= C_min + band
  double inversion_floor = kDefaultInversionFloor;            // s_i >= s_floor; 0 = none
};

// Converts validated settings into kappa and capped deviations (docs/math.md §3), and picks the
// evaluated projection (equal hyperbolic limits -> ellipsoid).
StrainLimitParams CalcStrainLimitParams(const StrainLimitSettings& settings);

// The limit frame Q of element e: element_frames[e] when given, else the body frame.
const Mat3& SelectStrainLimitFrame(const StrainLimitSettings& settings, int element);

// Name of a projection mode for messages and file output ("hyperbolic", ...).
const char* GetStrainProjectionName(StrainProjection projection);

}  // namespace taut
