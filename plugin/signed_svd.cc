#include "plugin/signed_svd.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

namespace taut {
namespace {

// Cyclic Jacobi stops when every off-diagonal entry of the Gram matrix is below this times its
// trace; quadratic convergence gets there in 3-5 sweeps, kMaxSweeps is a safety cap.
constexpr double kOffDiagonalTolerance = 1e-15;
constexpr int kMaxSweeps = 10;
// Below this a^2 + b^2 may have lost bits to underflow; Radius then uses std::hypot.
constexpr double kTinySquare = 1e-280;

// Plane rotation J in the (i, j) plane: J_ii = J_jj = c, J_ij = s, J_ji = -s. M J maps the
// columns (m_i, m_j) to (c m_i - s m_j, s m_i + c m_j); J^T M does the same to the rows.
struct Rotation {
  double c = 1.0;
  double s = 0.0;
};

// Quarter turn (c, s) = (0, -1): (m_i, m_j) -> (m_j, -m_i), a swap that keeps det = +1.
constexpr Rotation kQuarterTurn{0.0, -1.0};

// Columns (m_i, m_j) of M -> (c m_i - s m_j, s m_i + c m_j), i.e. M <- M J.
void RotateColumns(Mat3& M, int i, int j, Rotation r) {
  const Vec3 mi = M.col(i);
  M.col(i) = r.c * mi - r.s * M.col(j);
  M.col(j) = r.s * mi + r.c * M.col(j);
}

// Rows (m_i, m_j) of M -> (c m_i - s m_j, s m_i + c m_j), i.e. M <- J^T M.
void RotateRows(Mat3& M, int i, int j, Rotation r) {
  const Eigen::RowVector3d mi = M.row(i);
  M.row(i) = r.c * mi - r.s * M.row(j);
  M.row(j) = r.s * mi + r.c * M.row(j);
}

// Exact Jacobi rotation zeroing a_pq of the symmetric [[a_pp, a_pq], [a_pq, a_qq]] under J^T A J.
// With h = a_qq - a_pp and tau = h / (2 a_pq), t = tan(theta) = sign(tau) / (|tau| + sqrt(1 +
// tau^2)) (the smaller root, |theta| <= pi/4), c = 1 / sqrt(1 + t^2), s = t c; the new diagonal
// is (a_pp - t a_pq, a_qq + t a_pq). Evaluated in one of three equivalent forms:
//  - |x| = |a_pq / h| < 1e-3 (the last sweeps): t = 2x / (1 + sqrt(1 + 4x^2)) = x - x^3 + 2x^5
//    - ..., c = 1 - t^2/2 + 3t^4/8 - ..., cut where the next term is below 5e-18 relative: the
//    same values rounded to double, without square roots;
//  - otherwise, with g = 2 a_pq sign(h) (sign(0) = 1), r = sqrt(h^2 + g^2) and w = |h| + r:
//    t = g / w, c = w / sqrt(2 r w), s = g / sqrt(2 r w) (one division fewer than via tau);
//  - the tau form itself when h^2 + g^2 is near underflow.
Rotation JacobiRotation(double a_pp, double a_pq, double a_qq, double* t_out) {
  const double h = a_qq - a_pp;
  if (std::abs(a_pq) < 1e-3 * std::abs(h)) {
    const double x = a_pq / h, x2 = x * x;
    const double t = x * (1.0 - x2 * (1.0 - 2.0 * x2));
    const double t2 = t * t;
    const double c = 1.0 - t2 * (0.5 - 0.375 * t2);
    *t_out = t;
    return {c, t * c};
  }
  const double g = h >= 0.0 ? 2.0 * a_pq : -2.0 * a_pq;
  const double r2 = h * h + g * g;
  if (r2 < kTinySquare) {
    const double tau = h / (2.0 * a_pq);
    const double t = std::copysign(1.0 / (std::abs(tau) + std::sqrt(1.0 + tau * tau)), tau);
    const double c = 1.0 / std::sqrt(1.0 + t * t);
    *t_out = t;
    return {c, t * c};
  }
  const double r = std::sqrt(r2);
  const double w = std::abs(h) + r;
  const double inv_norm = 1.0 / std::sqrt(2.0 * r * w);
  *t_out = g / w;
  return {w * inv_norm, g * inv_norm};
}

// x 2^e, exact while the result is a normal number: one multiply by 2^e built from its exponent
// bits, std::scalbn when 2^e itself is not a normal double.
double ScaleByPowerOfTwo(double x, int e) {
  if (std::abs(e) >= 1000) return std::scalbn(x, e);
  const std::uint64_t bits = static_cast<std::uint64_t>(e + 1023) << 52;
  double power;
  std::memcpy(&power, &bits, sizeof(power));
  return x * power;
}

// One Jacobi step on the (p, q) pair of the symmetric S, skipped when |S_pq| <= threshold:
// S <- J^T S J (S_pq = 0), V <- V J. Returns whether it rotated.
template <int p, int q>
bool RotatePair(Mat3& S, Mat3& V, double threshold) {
  constexpr int r = 3 - p - q;
  if (std::abs(S(p, q)) <= threshold) return false;
  double t;
  const Rotation rot = JacobiRotation(S(p, p), S(p, q), S(q, q), &t);
  S(p, p) -= t * S(p, q);
  S(q, q) += t * S(p, q);
  S(p, q) = S(q, p) = 0.0;
  const double s_rp = S(r, p), s_rq = S(r, q);
  S(r, p) = S(p, r) = rot.c * s_rp - rot.s * s_rq;
  S(r, q) = S(q, r) = rot.s * s_rp + rot.c * s_rq;
  RotateColumns(V, p, q, rot);
  return true;
}

// Cyclic Jacobi on the symmetric S until |S_pq| <= kOffDiagonalTolerance trace(S) for every
// p < q: S <- V^T S V diagonal, V a rotation (a product of plane rotations).
Mat3 DiagonalizeSymmetric(Mat3& S) {
  Mat3 V = Mat3::Identity();
  const double threshold = kOffDiagonalTolerance * S.trace();
  for (int sweep = 0; sweep < kMaxSweeps; ++sweep) {
    const bool r01 = RotatePair<0, 1>(S, V, threshold);
    const bool r02 = RotatePair<0, 2>(S, V, threshold);
    const bool r12 = RotatePair<1, 2>(S, V, threshold);
    if (!(r01 || r02 || r12)) break;
  }
  return V;
}

// Swaps d_i, d_j and the columns v_i, v_j (as (v_j, -v_i), so det V stays +1) when d_i < d_j.
void OrderPair(Vec3& d, Mat3& V, int i, int j) {
  if (d[i] >= d[j]) return;
  std::swap(d[i], d[j]);
  RotateColumns(V, i, j, kQuarterTurn);
}

// Sorts the eigenvalues d descending and permutes V's columns with them (V stays a rotation).
void SortDescending(Vec3& d, Mat3& V) {
  OrderPair(d, V, 0, 1);
  OrderPair(d, V, 0, 2);
  OrderPair(d, V, 1, 2);
}

// Radius sqrt(a^2 + b^2) of an already squared sum r2 = a^2 + b^2 (std::hypot near underflow).
double Radius(double r2, double a, double b) {
  return r2 > kTinySquare ? std::sqrt(r2) : std::hypot(a, b);
}

// Rows i, j of B and columns i, j of U rotated by J: B <- J^T B, U <- U J (B = U R kept).
void ApplyGivens(Mat3& B, Mat3& U, int i, int j, Rotation rot) {
  RotateRows(B, i, j, rot);
  B(j, i) = 0.0;
  RotateColumns(U, i, j, rot);
}

// Zeroes B_10 and B_20 by J_01 then J_02. With (a, b, c) = column 0, J_01 maps (a, b) to
// (r_1, 0), r_1 = sqrt(a^2 + b^2), and J_02 maps (r_1, c) to (|b_0|, 0): both radii are known
// up front, so the two square roots do not wait on each other.
void ZeroFirstColumn(Mat3& B, Mat3& U) {
  const double a = B(0, 0), b = B(1, 0), c = B(2, 0);
  const double r1_2 = a * a + b * b;
  const double r1 = Radius(r1_2, a, b);
  const double r0 = c == 0.0 ? r1 : Radius(r1_2 + c * c, r1, c);
  if (r1 != 0.0) ApplyGivens(B, U, 0, 1, {a / r1, -b / r1});
  if (c != 0.0) ApplyGivens(B, U, 0, 2, {r1 / r0, -c / r0});
}

// Zeroes B_21 by J_12 (a Givens rotation of rows 1, 2; identity when B_21 = 0).
void ZeroSecondColumn(Mat3& B, Mat3& U) {
  const double a = B(1, 1), b = B(2, 1);
  if (b == 0.0) return;
  const double r = Radius(a * a + b * b, a, b);
  ApplyGivens(B, U, 1, 2, {a / r, -b / r});
}

// B = U R by three Givens rotations (zeroing B_10, B_20, B_21): U a rotation, R upper triangular
// with R_00, R_11 >= 0, R_22 carrying sign(det B). B becomes R.
Mat3 FactorQr(Mat3& B) {
  Mat3 U = Mat3::Identity();
  ZeroFirstColumn(B, U);
  ZeroSecondColumn(B, U);
  return U;
}

// Diagonalizes R's trailing block T = [[R_11, R_12], [0, R_22]] by the same two stages in 2x2:
// a Jacobi rotation J of T^T T (sorted descending; R <- R J, V <- V J), then the Givens rotation
// K zeroing (T J)_21 (R <- K^T R, U <- U K). Needed when s_2, s_3 are both below sqrt(eps) s_1:
// G^T G then carries too few bits to separate v_2 from v_3, and R_12 ~ s_2 instead of ~ eps s_1.
void SplitTrailingBlock(Mat3& R, Mat3& U, Mat3& V) {
  // Dropping R_12 costs |R_12| <= eps s_1 of accuracy when it is this small.
  if (std::abs(R(1, 2)) <= kOffDiagonalTolerance * R(0, 0)) return;
  // T / 2^e with max |T_ij| / 2^e in [1, 2) keeps the squares clear of underflow.
  const int e = -std::ilogb(std::max({std::abs(R(1, 1)), std::abs(R(1, 2)), std::abs(R(2, 2))}));
  const double a = ScaleByPowerOfTwo(R(1, 1), e), b = ScaleByPowerOfTwo(R(1, 2), e);
  const double d = ScaleByPowerOfTwo(R(2, 2), e);
  // T^T T = [[a^2, a b], [a b, b^2 + d^2]].
  const double p = a * a, q = a * b, r = b * b + d * d;
  if (q != 0.0) {
    double t;
    const Rotation rot = JacobiRotation(p, q, r, &t);
    RotateColumns(R, 1, 2, rot);
    RotateColumns(V, 1, 2, rot);
    if (r + t * q > p - t * q) {
      RotateColumns(R, 1, 2, kQuarterTurn);
      RotateColumns(V, 1, 2, kQuarterTurn);
    }
  } else if (r > p) {
    RotateColumns(R, 1, 2, kQuarterTurn);
    RotateColumns(V, 1, 2, kQuarterTurn);
  }
  ZeroSecondColumn(R, U);
  R(1, 2) = 0.0;
}

// Swaps s_i, s_j with u_i, u_j and v_i, v_j (both as quarter turns: u_i s v_i^T terms and
// det U = det V = +1 kept) when |s_i| < |s_j|.
void OrderBySize(Vec3& s, Mat3& U, Mat3& V, int i, int j) {
  if (std::abs(s[i]) >= std::abs(s[j])) return;
  std::swap(s[i], s[j]);
  RotateColumns(U, i, j, kQuarterTurn);
  RotateColumns(V, i, j, kQuarterTurn);
}

// Sorts |s| descending, then moves any negative sign of s_1, s_2 onto s_3: negating s_k, u_k,
// s_3 and u_3 together keeps U diag(s) and det U.
void SortAndSign(Vec3& s, Mat3& U, Mat3& V) {
  OrderBySize(s, U, V, 0, 1);
  OrderBySize(s, U, V, 0, 2);
  OrderBySize(s, U, V, 1, 2);
  for (int k = 0; k < 2; ++k) {
    if (s[k] >= 0.0) continue;
    s[k] = -s[k];
    s[2] = -s[2];
    U.col(k) = -U.col(k);
    U.col(2) = -U.col(2);
  }
}

}  // namespace

SignedSvd CalcSignedSvd(const Mat3& G) {
  if (!G.allFinite()) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    return {Mat3::Constant(nan), Vec3::Constant(nan), Mat3::Constant(nan)};
  }
  if ((G.array() == 0.0).all()) return {Mat3::Identity(), Vec3::Zero(), Mat3::Identity()};
  // A = G / 2^e with max |A_ij| in [1, 2) (exact): the method is scale-invariant, s = 2^e s(A).
  const int e = std::ilogb(G.cwiseAbs().maxCoeff());
  const Mat3 A = G.unaryExpr([e](double x) { return ScaleByPowerOfTwo(x, -e); });
  // V^T (A^T A) V = diag(s^2), sorted descending.
  Mat3 S = A.transpose() * A;
  Mat3 V = DiagonalizeSymmetric(S);
  Vec3 d = S.diagonal();
  SortDescending(d, V);
  // A V = U R with R diagonal up to round-off (its columns are orthogonal): s = diag(R).
  Mat3 R = A * V;
  Mat3 U = FactorQr(R);
  SplitTrailingBlock(R, U, V);
  Vec3 s = R.diagonal();
  SortAndSign(s, U, V);
  for (int k = 0; k < 3; ++k) s[k] = ScaleByPowerOfTwo(s[k], e);
  return {U, s, V};
}

Mat3 CalcPolarRotationBySvd(const Mat3& G) {
  const SignedSvd svd = CalcSignedSvd(G);
  return svd.U * svd.V.transpose();
}

}  // namespace taut
