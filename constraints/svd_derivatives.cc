#include "constraints/svd_derivatives.h"

#include <algorithm>
#include <cmath>

namespace taut {

double CalcClampedGapDenominator(const Vec3& s, int i, int m, double epsilon) {
  TAUT_ASSERT(i != m);
  // Clamp the canonically ordered pair (a < b), then flip the sign for (b, a) (R1).
  const int a = std::min(i, m);
  const int b = std::max(i, m);
  const double D = s[a] * s[a] - s[b] * s[b];
  double clamped = D;
  if (std::abs(D) < epsilon) clamped = D >= 0.0 ? epsilon : -epsilon;
  return i == a ? clamped : -clamped;
}

bool IsSvdGapClampActive(const Vec3& s, int i, double epsilon) {
  for (int m = 0; m < 3; ++m) {
    if (m == i) continue;
    if (std::abs(s[i] * s[i] - s[m] * s[m]) < epsilon) return true;
  }
  return false;
}

Vec12 CalcSingularValueGradient(const SignedSvd& svd, const TetRestRows& r, int i) {
  // Eq. 13: ds_i/dx_n = (r_n . v_i) u_i.
  const Vec3 v_i = svd.V.col(i);
  const Vec3 u_i = svd.U.col(i);
  Vec12 grad;
  for (int n = 0; n < 4; ++n) grad.segment<3>(3 * n) = r[n].dot(v_i) * u_i;
  return grad;
}

Mat3x12 CalcSingularVectorGradient(const SignedSvd& svd, const TetRestRows& r, int i,
                                   double gap_epsilon) {
  const Mat3& U = svd.U;
  const Mat3& V = svd.V;
  const Vec3& s = svd.s;
  Mat3x12 grad = Mat3x12::Zero();
  for (int n = 0; n < 4; ++n) {
    // a[m] = r_n . v_m.
    const Vec3 a = V.transpose() * r[n];
    auto block = grad.block<3, 3>(0, 3 * n);
    for (int m = 0; m < 3; ++m) {
      if (m == i) continue;
      // docs/math.md §2.2: v_m [s_m (r_n.v_i) u_m^T + s_i (r_n.v_m) u_i^T] / D_im.
      const double inv_D = 1.0 / CalcClampedGapDenominator(s, i, m, gap_epsilon);
      const Vec3 row = (s[m] * a[i] * inv_D) * U.col(m) + (s[i] * a[m] * inv_D) * U.col(i);
      block.noalias() += V.col(m) * row.transpose();
    }
  }
  return grad;
}

SvdDifferential CalcSvdDifferential(const SignedSvd& svd, const Mat3& dG, double gap_epsilon) {
  const Vec3& s = svd.s;
  const Mat3 P = svd.U.transpose() * dG * svd.V;
  Mat3 omega_U = Mat3::Zero();
  Mat3 omega_V = Mat3::Zero();
  for (int i = 0; i < 3; ++i) {
    for (int m = 0; m < 3; ++m) {
      if (m == i) continue;
      // PL 2x2 solve (docs/math.md §2.1) with a = m, b = i.
      const double D = CalcClampedGapDenominator(s, i, m, gap_epsilon);
      omega_V(m, i) = (s[m] * P(m, i) + s[i] * P(i, m)) / D;
      omega_U(m, i) = (s[i] * P(m, i) + s[m] * P(i, m)) / D;
    }
  }
  return SvdDifferential{svd.U * omega_U, P.diagonal(), svd.V * omega_V};
}

}  // namespace taut
