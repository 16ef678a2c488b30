#include "constraints/strain_limit_curvature.h"

#include <cmath>

namespace taut {

double CalcStrainRowStretchSlope(const Mat3& V_prime, int i, const StrainLimitParams& params,
                                 const StrainLimitKey& key) {
  // Floor: C = (s_i - s_floor) / (1 - s_floor) (docs/math.md §3.8).
  if (key.axis == kStrainFloorAxis) return 1.0 / (1.0 - params.inversion_floor);
  const bool is_max = key.bound == StrainBound::kMax;
  const Vec3 w = V_prime.col(i);
  switch (params.projection) {
    case StrainProjection::kHyperbolic: {
      // C = 1 - kappa^j |V'_ji| |s_i - 1| (eqs. 11-12 times kappa^j).
      const Vec3& kappa = is_max ? params.kappa_max : params.kappa_min;
      return kappa[key.axis] * std::abs(w[key.axis]);
    }
    case StrainProjection::kOrthogonal: {
      // C = |V'_ji| - |s_i - 1| / |d^j| (eqs. 19-20 divided by |d^j|).
      const Vec3& d = is_max ? params.d_max_capped : params.d_min_capped;
      return 1.0 / std::abs(d[key.axis]);
    }
    case StrainProjection::kLinearInterpolation: {
      // C = 1 - |s_i - 1| / |L - 1|, L = ||diag(s^j) w|| (eqs. 21-22).
      const Vec3 s_cap = Vec3::Ones() + (is_max ? params.d_max_capped : params.d_min_capped);
      return 1.0 / std::abs(s_cap.cwiseProduct(w).norm() - 1.0);
    }
    case StrainProjection::kEllipsoid:
      // C = 1 - |s_i - 1| ||K w|| (docs/math.md §3.5).
      return (is_max ? params.kappa_max : params.kappa_min).cwiseProduct(w).norm();
  }
  return 0.0;
}

Mat12 CalcStrainLimitRowCurvature(const TetRestRows& r, const SignedSvd& svd, const Mat3& Q,
                                  const StrainLimitParams& params, const StrainLimitKey& key) {
  // The key names v_i by its matched material axis (R3), so find i at this SVD.
  const Mat3 V_prime = Q.transpose() * svd.V;
  const int i = FindMatchedPrincipalIndex(CalcPrincipalAxisMatch(V_prime), key.principal_axis);
  const double slope = CalcStrainRowStretchSlope(V_prime, i, params, key);
  // -d^2C = +kappa_eff d^2 s_i (C decreasing in s_i) or -kappa_eff d^2 s_i (increasing).
  const double scale = key.bound == StrainBound::kMax ? slope : -slope;
  const SingularValueHessian hessian = CalcSingularValueHessian(svd, i, params.svd_gap_epsilon);
  return CalcTetSingularValueHessian(hessian, r, scale, /*clamp_negative=*/true);
}

}  // namespace taut
