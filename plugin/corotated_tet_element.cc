#include "plugin/corotated_tet_element.h"

#include <cmath>

#include "plugin/signed_svd.h"

namespace taut {

double CalcCorotatedTetEnergy(const TetRestElement& rest, const LameParameters& lame, const Mat3& G,
                              const Mat3& R) {
  const Mat3 eps = R.transpose() * G - Mat3::Identity();
  const double tr = eps.trace();
  return rest.volume * (lame.mu * eps.squaredNorm() + 0.5 * lame.lambda * tr * tr);
}

double CalcCorotatedTetEnergyBound(const TetRestElement& rest, const LameParameters& lame,
                                   const Mat3& G) {
  // sum_i (s_i - 1)^2 <= sum_i (s_i^2 - 1)^2 = ||G^T G - I||_F^2 for s_i > 0, and
  // tr(S - I)^2 <= 3 ||S - I||_F^2 (docs/math.md §4.6).
  if (!(G.determinant() > 0.0)) return HUGE_VAL;
  const double strain = (G.transpose() * G - Mat3::Identity()).squaredNorm();
  return rest.volume * (lame.mu + 1.5 * std::max(lame.lambda, 0.0)) * strain;
}

Mat3 CalcCorotatedStress(const LameParameters& lame, const Mat3& G, const Mat3& R) {
  const double tr = (R.transpose() * G).trace() - 3.0;
  return 2.0 * lame.mu * (G - R) + lame.lambda * tr * R;
}

std::array<Vec3, 4> CalcCorotatedTetForces(const TetRestElement& rest, const LameParameters& lame,
                                           const Mat3& G, const Mat3& R) {
  const Mat3 P = CalcCorotatedStress(lame, G, R);
  std::array<Vec3, 4> f;
  for (int n = 0; n < 4; ++n) f[n] = -rest.volume * (P * rest.r[n]);
  return f;
}

Mat3 CalcRestStiffnessBlock(const TetRestElement& rest, const LameParameters& lame, int n, int m) {
  const Vec3& rn = rest.r[n];
  const Vec3& rm = rest.r[m];
  Mat3 K = lame.lambda * rn * rm.transpose() + lame.mu * rm * rn.transpose();
  K.diagonal().array() += lame.mu * rn.dot(rm);
  return rest.volume * K;
}

Mat12 CalcFrozenRotationTetStiffness(const TetRestElement& rest, const LameParameters& lame,
                                     const Mat3& R) {
  Mat12 K;
  for (int n = 0; n < 4; ++n)
    for (int m = 0; m < 4; ++m)
      K.block<3, 3>(3 * n, 3 * m) = R * CalcRestStiffnessBlock(rest, lame, n, m) * R.transpose();
  return K;
}

namespace {
// vee of a skew matrix: (M32, M13, M21).
Vec3 Vee(const Mat3& M) { return Vec3(M(2, 1), M(0, 2), M(1, 0)); }
// hat(w) v = w x v.
Mat3 Hat(const Vec3& w) {
  Mat3 H;
  H << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
  return H;
}
}  // namespace

Mat12 CalcExactTetStiffness(const TetRestElement& rest, const LameParameters& lame,
                            const std::array<Vec3, 4>& x, double clamp) {
  const Mat3 G = CalcTetDeformationGradient(rest, x);
  const SignedSvd svd = CalcSignedSvd(G);
  const Mat3 R = svd.U * svd.V.transpose();
  const Mat3 S = R.transpose() * G;
  // (tr S I - S)^-1 = V diag(1 / (s_b + s_c)) V^T, denominators clamped away from zero.
  Vec3 inv;
  for (int a = 0; a < 3; ++a) {
    double d = svd.s.sum() - svd.s[a];
    if (std::abs(d) < clamp) d = d < 0.0 ? -clamp : clamp;
    inv[a] = 1.0 / d;
  }
  const Mat3 T_inv = svd.V * inv.asDiagonal() * svd.V.transpose();
  const double tr_eps = S.trace() - 3.0;
  Mat12 K;
  for (int m = 0; m < 4; ++m) {
    for (int k = 0; k < 3; ++k) {
      // Perturbation dG = e_k r_m^T of node m, component k.
      const Mat3 dG = Vec3::Unit(k) * rest.r[m].transpose();
      const Mat3 RtdG = R.transpose() * dG;
      const Mat3 dR = R * Hat(T_inv * Vee(RtdG - RtdG.transpose()));
      const Mat3 dP =
          2.0 * lame.mu * (dG - dR) + lame.lambda * RtdG.trace() * R + lame.lambda * tr_eps * dR;
      for (int n = 0; n < 4; ++n) K.block<3, 1>(3 * n, 3 * m + k) = rest.volume * (dP * rest.r[n]);
    }
  }
  return K;
}

}  // namespace taut
