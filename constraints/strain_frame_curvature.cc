#include "constraints/strain_frame_curvature.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <cmath>

namespace taut {
namespace {

using Vec9 = Eigen::Matrix<double, 9, 1>;

constexpr double kInvSqrt2 = 0.70710678118654752440;

// Index of P_xy in vec(P).
int P(int x, int y) { return 3 * x + y; }

bool IsUniform(const Vec3& a) { return a[0] == a[1] && a[1] == a[2]; }

// A linear form over vec(P) with at most four nonzero coefficients: the first-order forms below
// touch one or two entries of P, and a's gradient is the sum of two of them. Kept sparse because
// the quadratic forms built from them are the frame curvature's main cost (docs/solver.md).
struct SparseForm {
  int size = 0;
  int index[4] = {0, 0, 0, 0};
  double value[4] = {0.0, 0.0, 0.0, 0.0};

  void Add(int i, double v) {
    for (int k = 0; k < size; ++k)
      if (index[k] == i) {
        value[k] += v;
        return;
      }
    TAUT_ASSERT(size < 4);
    index[size] = i;
    value[size++] = v;
  }
  // this += w b.
  void AddScaled(double w, const SparseForm& b) {
    for (int k = 0; k < b.size; ++k) Add(b.index[k], w * b.value[k]);
  }
};

// (C1)_xy = s_x P_xy + s_y P_yx as a linear form over vec(P).
SparseForm FirstOrderForm(const Vec3& s, int x, int y) {
  SparseForm form;
  form.Add(P(x, y), s[x]);
  form.Add(P(y, x), s[y]);
  return form;
}

SparseForm UnitForm(int index) {
  SparseForm form;
  form.Add(index, 1.0);
  return form;
}

// H += w (a . p)(b . p) as a symmetric matrix: w (a b^T + b a^T) / 2.
void AddSymmetricProduct(double w, const SparseForm& a, const SparseForm& b, Mat9& H) {
  const double half_w = 0.5 * w;
  for (int p = 0; p < a.size; ++p)
    for (int q = 0; q < b.size; ++q) {
      const double t = half_w * a.value[p] * b.value[q];
      H(a.index[p], b.index[q]) += t;
      H(b.index[q], a.index[p]) += t;
    }
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
    SparseForm symmetric, antisymmetric;
    symmetric.Add(P(i, j), kInvSqrt2);
    symmetric.Add(P(j, i), kInvSqrt2);
    antisymmetric.Add(P(i, j), kInvSqrt2);
    antisymmetric.Add(P(j, i), -kInvSqrt2);
    AddSymmetricProduct(1.0 / ClampGap(s[i] - s[j], rho), symmetric, symmetric, H);
    AddSymmetricProduct(1.0 / ClampGap(s[i] + s[j], rho), antisymmetric, antisymmetric, H);
  }
  return H;
}

// d^2 a over vec(P) and da, for a = sqrt(v_i^T M v_i), M~ = V^T M V (see the header).
struct FrameFactorDerivatives {
  double a = 0.0;
  SparseForm gradient;
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
  // v'_j = g_j (C1)_ji for j != i.
  SparseForm dv[3];
  for (int j = 0; j < 3; ++j)
    if (j != i) dv[j].AddScaled(g[j], FirstOrderForm(s, j, i));
  // a' = (M~ v')_i / a.
  for (int j = 0; j < 3; ++j) out.gradient.AddScaled(M_tilde(i, j) / out.a, dv[j]);
  // v'^T M~ v'.
  Mat9& q = out.hessian;
  for (int j = 0; j < 3; ++j)
    for (int k = 0; k < 3; ++k)
      if (j != i && k != i) AddSymmetricProduct(M_tilde(j, k), dv[j], dv[k], q);
  // (M~ e_i) . v'', v''_j = -2 g_j^2 (C1)_ii (C1)_ji + 2 g_j sum_k g_k (C1)_jk (C1)_ki
  // + g_j (C2)_ji, and the normalization's -M~_ii g_j^2 ((C1)_ji)^2.
  const SparseForm l_ii = FirstOrderForm(s, i, i);
  for (int j = 0; j < 3; ++j) {
    if (j == i) continue;
    const double w = M_tilde(j, i);
    const SparseForm l_ji = FirstOrderForm(s, j, i);
    AddSymmetricProduct(-2.0 * w * g[j] * g[j], l_ii, l_ji, q);
    for (int k = 0; k < 3; ++k)
      if (k != i)
        AddSymmetricProduct(2.0 * w * g[j] * g[k], FirstOrderForm(s, j, k), FirstOrderForm(s, k, i),
                            q);
    // (C2)_ji = 2 sum_r P_rj P_ri.
    for (int r = 0; r < 3; ++r)
      AddSymmetricProduct(2.0 * w * g[j], UnitForm(P(r, j)), UnitForm(P(r, i)), q);
    AddSymmetricProduct(-M_tilde(i, i) * g[j] * g[j], l_ji, l_ji, q);
  }
  // d^2 a = (q - a' a'^T) / a.
  AddSymmetricProduct(-1.0, out.gradient, out.gradient, q);
  q /= out.a;
  return out;
}

}  // namespace

bool HasStrainFrameCurvature(const StrainLimitParams& params) {
  if (params.freeze_frame_jacobian || !params.full_frame_curvature) return false;
  if (params.projection == StrainProjection::kHyperbolic) return true;
  return params.projection == StrainProjection::kEllipsoid &&
         !(IsUniform(params.kappa_max) && IsUniform(params.kappa_min));
}

bool HasExactStrainCurvature(const StrainLimitParams& params) {
  return HasStrainFrameCurvature(params) ||
         (params.projection == StrainProjection::kEllipsoid && IsUniform(params.kappa_max) &&
          IsUniform(params.kappa_min));
}

Mat9 CalcPrincipalStrainRowCurvature(const SignedSvd& svd, const Mat3& Q,
                                     const StrainLimitParams& params, const StrainLimitKey& key) {
  TAUT_ASSERT(params.projection == StrainProjection::kHyperbolic ||
              params.projection == StrainProjection::kEllipsoid);
  const Mat3 V_prime = Q.transpose() * svd.V;
  // The key names v_i by its matched material axis (R3), so find i at this SVD.
  const int i = FindMatchedPrincipalIndex(CalcPrincipalAxisMatch(V_prime), key.principal_axis);
  // Floor rows have no frame factor: -d^2 C = -d^2 s_i / (1 - s_floor) (docs/math.md §3.8).
  if (key.axis == kStrainFloorAxis) {
    return (-1.0 / (1.0 - params.inversion_floor)) *
           CalcStretchHessian(svd.s, i, params.svd_gap_epsilon);
  }
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
  Mat9 H =
      a.a * CalcStretchHessian(svd.s, i, params.svd_gap_epsilon) + (svd.s[i] - 1.0) * a.hessian;
  AddSymmetricProduct(2.0, UnitForm(P(i, i)), a.gradient, H);
  return sigma * H;
}

Mat9 ClampNegativeModes(const Mat9& H, double kept_fraction) {
  // A Cholesky factor of H + delta I (9^3/3 flops, a tenth of the eigen-decomposition) proves
  // lambda_min(H) > -delta, delta = kept_fraction max |H_kk|, and H is kept as it is (its
  // eigenvalues in (-delta, 0) are left unclamped).
  const double delta = kept_fraction * H.diagonal().cwiseAbs().maxCoeff();
  if (delta > 0.0) {
    const Eigen::LLT<Mat9> cholesky(H + delta * Mat9::Identity());
    if (cholesky.info() == Eigen::Success) return H;
  }
  const Eigen::SelfAdjointEigenSolver<Mat9> eigen(H);
  const Vec9 clamped = eigen.eigenvalues().cwiseMax(0.0);
  return eigen.eigenvectors() * clamped.asDiagonal() * eigen.eigenvectors().transpose();
}

Mat12 MapPrincipalHessianToTet(const Mat9& H, const SignedSvd& svd, const TetRestRows& r) {
  // dP_xy/dx_{n,k} = U_kx (V^T r_n)_y, so W^T H W factors through the two 3x3 frames:
  // G[(k,y),(l,y')] = sum_{x,x'} U_kx H[(x,y),(x',y')] U_lx' (U on the left index), then
  // block (k,l) of the result over nodes (n,m) is R_hat G_kl R_hat^T with R_hat's rows
  // (V^T r_n)^T. About half the flops of the dense 9x12 product, and no general product kernel.
  Eigen::Matrix<double, 4, 3> r_hat;
  for (int n = 0; n < 4; ++n) r_hat.row(n) = (svd.V.transpose() * r[n]).transpose();
  Mat3 G[3][3];  // G[k][l](y, y')
  for (int y = 0; y < 3; ++y) {
    for (int y2 = y; y2 < 3; ++y2) {
      Mat3 B;  // B(x, x') = H[(x,y),(x',y')]
      for (int x = 0; x < 3; ++x)
        for (int x2 = 0; x2 < 3; ++x2) B(x, x2) = H(P(x, y), P(x2, y2));
      const Mat3 UBUt = svd.U * B * svd.U.transpose();
      for (int k = 0; k < 3; ++k)
        for (int l = 0; l < 3; ++l) {
          G[k][l](y, y2) = UBUt(k, l);
          G[l][k](y2, y) = UBUt(k, l);  // H symmetric: G[(l,y'),(k,y)] = G[(k,y),(l,y')]
        }
    }
  }
  Mat12 out;
  for (int k = 0; k < 3; ++k) {
    for (int l = k; l < 3; ++l) {
      const Eigen::Matrix4d block = r_hat * G[k][l] * r_hat.transpose();
      for (int n = 0; n < 4; ++n)
        for (int m = 0; m < 4; ++m) {
          out(3 * n + k, 3 * m + l) = block(n, m);
          out(3 * m + l, 3 * n + k) = block(n, m);
        }
    }
  }
  return out;
}

}  // namespace taut
