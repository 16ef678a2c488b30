#include "constraints/strain_frame_curvature.h"

#include <Eigen/Eigenvalues>
#include <cmath>

namespace taut {
namespace {

using Vec9 = Eigen::Matrix<double, 9, 1>;

constexpr double kInvSqrt2 = 0.70710678118654752440;

// Index of P_xy in vec(P).
int P(int x, int y) { return 3 * x + y; }

bool IsUniform(const Vec3& a) { return a[0] == a[1] && a[1] == a[2]; }

// (C1)_xy = s_x P_xy + s_y P_yx as a linear form over vec(P).
Vec9 FirstOrderForm(const Vec3& s, int x, int y) {
  Vec9 form = Vec9::Zero();
  form[P(x, y)] += s[x];
  form[P(y, x)] += s[y];
  return form;
}

// The quadratic form (a . p)(b . p) as a symmetric matrix: (a b^T + b a^T) / 2.
Mat9 SymmetricProduct(const Vec9& a, const Vec9& b) {
  return 0.5 * (a * b.transpose() + b * a.transpose());
}

// d with |d| raised to at least rho, keeping its sign (sgn(0) := +1; docs/math.md §2 R1).
double ClampGap(double d, double rho) {
  if (std::abs(d) >= rho) return d;
  return d >= 0.0 ? rho : -rho;
}

// d^2 s_i over vec(P): sum_{j != i} alpha_j^2 / (s_i - s_j) + beta_j^2 / (s_i + s_j), the
// symmetric and antisymmetric pair modes (constraints/singular_value_hessian.h, same clamp).
Mat9 CalcStretchHessian(const Vec3& s, int i, double gap_epsilon) {
  Mat9 H = Mat9::Zero();
  for (int j = 0; j < 3; ++j) {
    if (j == i) continue;
    const double rho = gap_epsilon / (std::abs(s[i]) + std::abs(s[j]));
    Vec9 symmetric = Vec9::Zero(), antisymmetric = Vec9::Zero();
    symmetric[P(i, j)] = symmetric[P(j, i)] = kInvSqrt2;
    antisymmetric[P(i, j)] = kInvSqrt2;
    antisymmetric[P(j, i)] = -kInvSqrt2;
    H.noalias() += (1.0 / ClampGap(s[i] - s[j], rho)) * symmetric * symmetric.transpose();
    H.noalias() += (1.0 / ClampGap(s[i] + s[j], rho)) * antisymmetric * antisymmetric.transpose();
  }
  return H;
}

// d^2 a over vec(P) and da, for a = sqrt(v_i^T M v_i), M~ = V^T M V (see the header).
struct FrameFactorDerivatives {
  double a = 0.0;
  Vec9 gradient = Vec9::Zero();
  Mat9 hessian = Mat9::Zero();
};

FrameFactorDerivatives CalcFrameFactorDerivatives(const Vec3& s, int i, const Mat3& M_tilde,
                                                  double gap_epsilon) {
  FrameFactorDerivatives out;
  out.a = std::sqrt(std::max(M_tilde(i, i), 0.0));
  if (!(out.a > 0.0)) return out;
  // g_j = 1 / (s_i^2 - s_j^2), clamped as the first derivative's D_ij (R1).
  Vec3 g = Vec3::Zero();
  for (int j = 0; j < 3; ++j)
    if (j != i) g[j] = 1.0 / CalcClampedGapDenominator(s, i, j, gap_epsilon);
  // l[x][y] = (C1)_xy; v'_j = g_j l[j][i] for j != i.
  Vec9 l[3][3];
  for (int x = 0; x < 3; ++x)
    for (int y = 0; y < 3; ++y) l[x][y] = FirstOrderForm(s, x, y);
  Vec9 dv[3];
  for (int j = 0; j < 3; ++j) dv[j] = j == i ? Vec9::Zero() : Vec9(g[j] * l[j][i]);
  // a' = (M~ v')_i / a.
  for (int j = 0; j < 3; ++j) out.gradient += (M_tilde(i, j) / out.a) * dv[j];
  // v'^T M~ v'.
  Mat9 q = Mat9::Zero();
  for (int j = 0; j < 3; ++j)
    for (int k = 0; k < 3; ++k)
      if (j != i && k != i) q.noalias() += M_tilde(j, k) * SymmetricProduct(dv[j], dv[k]);
  // (M~ e_i) . v''.
  for (int j = 0; j < 3; ++j) {
    if (j == i) continue;
    Mat9 second = -2.0 * g[j] * g[j] * SymmetricProduct(l[i][i], l[j][i]);
    for (int k = 0; k < 3; ++k)
      if (k != i) second.noalias() += 2.0 * g[j] * g[k] * SymmetricProduct(l[j][k], l[k][i]);
    // (C2)_ji = 2 sum_r P_rj P_ri.
    for (int r = 0; r < 3; ++r) {
      Vec9 e_rj = Vec9::Zero(), e_ri = Vec9::Zero();
      e_rj[P(r, j)] = 1.0;
      e_ri[P(r, i)] = 1.0;
      second.noalias() += 2.0 * g[j] * SymmetricProduct(e_rj, e_ri);
    }
    q.noalias() += M_tilde(j, i) * second;
    q.noalias() -= M_tilde(i, i) * g[j] * g[j] * l[j][i] * l[j][i].transpose();
  }
  out.hessian = q / out.a - out.gradient * out.gradient.transpose() / out.a;
  return out;
}

}  // namespace

bool HasStrainFrameCurvature(const StrainLimitParams& params) {
  if (params.freeze_frame_jacobian || !params.full_frame_curvature) return false;
  if (params.projection == StrainProjection::kHyperbolic) return true;
  return params.projection == StrainProjection::kEllipsoid &&
         !(IsUniform(params.kappa_max) && IsUniform(params.kappa_min));
}

Mat9 CalcPrincipalStrainRowCurvature(const SignedSvd& svd, const Mat3& Q,
                                     const StrainLimitParams& params, const StrainLimitKey& key) {
  TAUT_ASSERT(params.projection == StrainProjection::kHyperbolic ||
              params.projection == StrainProjection::kEllipsoid);
  const Mat3 V_prime = Q.transpose() * svd.V;
  // The key names v_i by its matched material axis (R3), so find i at this SVD.
  const int i = FindMatchedPrincipalIndex(CalcPrincipalAxisMatch(V_prime), key.principal_axis);
  const bool is_max = key.bound == StrainBound::kMax;
  const double sigma = is_max ? 1.0 : -1.0;
  // M = Q diag(k^2) Q^T: k = kappa (ellipsoid) or kappa_j e_j (hyperbolic row (j, i)).
  Vec3 k = is_max ? params.kappa_max : params.kappa_min;
  if (params.projection == StrainProjection::kHyperbolic) {
    const double kappa_j = k[key.axis];
    k.setZero();
    k[key.axis] = kappa_j;
  }
  const Mat3 KV = k.asDiagonal() * V_prime;
  const Mat3 M_tilde = KV.transpose() * KV;
  const FrameFactorDerivatives a =
      CalcFrameFactorDerivatives(svd.s, i, M_tilde, params.svd_gap_epsilon);
  if (!(a.a > 0.0)) return Mat9::Zero();
  // -d^2 C = sigma [a d^2 s_i + 2 ds_i da + (s_i - 1) d^2 a], ds_i = P_ii.
  Vec9 ds = Vec9::Zero();
  ds[P(i, i)] = 1.0;
  const Mat9 H = a.a * CalcStretchHessian(svd.s, i, params.svd_gap_epsilon) +
                 2.0 * SymmetricProduct(ds, a.gradient) + (svd.s[i] - 1.0) * a.hessian;
  return sigma * H;
}

Mat9 ClampNegativeModes(const Mat9& H) {
  const Eigen::SelfAdjointEigenSolver<Mat9> eigen(H);
  const Vec9 clamped = eigen.eigenvalues().cwiseMax(0.0);
  return eigen.eigenvectors() * clamped.asDiagonal() * eigen.eigenvectors().transpose();
}

Mat12 MapPrincipalHessianToTet(const Mat9& H, const SignedSvd& svd, const TetRestRows& r) {
  // dP/dx_{n,k} = (U^T e_k)(V^T r_n)^T: entry (x, y) is U_kx (V^T r_n)_y.
  Eigen::Matrix<double, 9, 12> W;
  for (int n = 0; n < 4; ++n) {
    const Vec3 r_hat = svd.V.transpose() * r[n];
    for (int k = 0; k < 3; ++k)
      for (int x = 0; x < 3; ++x)
        for (int y = 0; y < 3; ++y) W(P(x, y), 3 * n + k) = svd.U(k, x) * r_hat[y];
  }
  return W.transpose() * H * W;
}

}  // namespace taut
