#include "constraints/singular_value_hessian.h"

#include <cmath>

namespace taut {
namespace {

constexpr double kInvSqrt2 = 0.70710678118654752440;

// d with |d| raised to at least rho, keeping its sign (sgn(0) := +1; docs/math.md §2 R1).
double ClampGap(double d, double rho) {
  if (std::abs(d) >= rho) return d;
  return d >= 0.0 ? rho : -rho;
}

}  // namespace

SingularValueHessian CalcSingularValueHessian(const SignedSvd& svd, int i, double gap_epsilon) {
  TAUT_ASSERT(i >= 0 && i < 3);
  const Vec3& s = svd.s;
  const Vec3 u_i = svd.U.col(i);
  const Vec3 v_i = svd.V.col(i);
  SingularValueHessian hessian;
  int k = 0;
  for (int j = 0; j < 3; ++j) {
    if (j == i) continue;
    const Vec3 u_j = svd.U.col(j);
    const Vec3 v_j = svd.V.col(j);
    // R1 in s units: |s_i^2 - s_j^2| >= epsilon  <=>  |s_i -+ s_j| >= epsilon / (|s_i| + |s_j|).
    const double rho = gap_epsilon / (std::abs(s[i]) + std::abs(s[j]));
    hessian.modes[k] = kInvSqrt2 * (u_i * v_j.transpose() + u_j * v_i.transpose());
    hessian.eigenvalues[k] = 1.0 / ClampGap(s[i] - s[j], rho);
    hessian.modes[k + 1] = kInvSqrt2 * (u_i * v_j.transpose() - u_j * v_i.transpose());
    hessian.eigenvalues[k + 1] = 1.0 / ClampGap(s[i] + s[j], rho);
    k += 2;
  }
  return hessian;
}

Mat9 CalcDenseSingularValueHessian(const SingularValueHessian& hessian) {
  Mat9 dense = Mat9::Zero();
  for (int k = 0; k < 4; ++k) {
    // Row-major vec(M): index 3 row + col.
    Eigen::Matrix<double, 9, 1> m;
    for (int row = 0; row < 3; ++row)
      for (int col = 0; col < 3; ++col) m[3 * row + col] = hessian.modes[k](row, col);
    dense.noalias() += hessian.eigenvalues[k] * m * m.transpose();
  }
  return dense;
}

Mat12 CalcTetSingularValueHessian(const SingularValueHessian& hessian, const TetRestRows& r,
                                  double scale, bool clamp_negative) {
  Mat12 H = Mat12::Zero();
  for (int k = 0; k < 4; ++k) {
    const double lambda = scale * hessian.eigenvalues[k];
    if (clamp_negative && !(lambda > 0.0)) continue;
    // <dF, M> = g . dx with g_n = M r_n: the mode adds lambda g g^T.
    Vec12 g;
    for (int n = 0; n < 4; ++n) g.segment<3>(3 * n) = hessian.modes[k] * r[n];
    H.noalias() += lambda * g * g.transpose();
  }
  return H;
}

}  // namespace taut
