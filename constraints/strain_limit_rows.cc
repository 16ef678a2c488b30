#include "constraints/strain_limit_rows.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "constraints/row_key_layouts.h"

namespace taut {
namespace {

constexpr std::array<std::array<int, 3>, 6> kPermutations = {
    {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};

// sgn with sgn(0) := 0 (docs/math.md §2 R2).
double Sign(double v) { return v > 0.0 ? 1.0 : (v < 0.0 ? -1.0 : 0.0); }

// True when all three entries are equal (then ||diag(a) w|| = a for unit w: dV/dx drops out).
bool IsIsotropic(const Vec3& a) { return a[0] == a[1] && a[1] == a[2]; }

// Row evaluation of one element: the per-principal derivatives are computed lazily, only for
// principal directions that emit a row with a Jacobian.
class RowEvaluator {
 public:
  RowEvaluator(int element, const TetRestRows& r, const SignedSvd& svd, const Mat3& Q,
               const StrainLimitParams& params, std::vector<StrainLimitRow>* rows)
      : element_(element),
        r_(r),
        svd_(svd),
        Q_(Q),
        params_(params),
        rows_(rows),
        V_prime_(Q.transpose() * svd.V),
        match_(CalcPrincipalAxisMatch(V_prime_)) {}

  // Evaluates every candidate row; emits those with C < tau when rows_ is set. Returns min C.
  double Run() {
    for (int i = 0; i < 3; ++i) {
      have_grad_ = false;
      const double e = svd_.s[i] - 1.0;
      // R2: C_max only where s_i > 1, C_min only where s_i < 1.
      if (e > 0.0 && params_.has_max) EvaluatePrincipal(i, StrainBound::kMax);
      if (e < 0.0 && params_.has_min) EvaluatePrincipal(i, StrainBound::kMin);
      if (params_.inversion_floor > 0.0) EvaluateFloor(i);
    }
    return min_C_;
  }

  // Number of rows appended by Run().
  int num_emitted() const { return num_emitted_; }

 private:
  // Rows of principal direction i on one bound side.
  void EvaluatePrincipal(int i, StrainBound bound) {
    switch (params_.projection) {
      case StrainProjection::kHyperbolic:
      case StrainProjection::kOrthogonal:
        EvaluatePerAxis(i, bound);
        break;
      case StrainProjection::kLinearInterpolation:
        EvaluateLinearInterpolation(i, bound);
        break;
      case StrainProjection::kEllipsoid:
        EvaluateEllipsoid(i, bound);
        break;
    }
  }

  // Hyperbolic (eqs. 11-12, 17-18) or orthogonal (eqs. 19-20) rows (j, i), j = 0..2. Hyperbolic
  // rows are filtered: only those with C_j <= min_j C_j + band (docs/math.md §3.7); every C_j
  // still counts for min C, so violations and the feasible set do not change.
  void EvaluatePerAxis(int i, StrainBound bound) {
    const bool hyperbolic = params_.projection == StrainProjection::kHyperbolic;
    std::array<double, 3> C;
    double C_dominant = std::numeric_limits<double>::infinity();
    for (int j = 0; j < 3; ++j) {
      C[j] = CalcPerAxisValue(i, j, bound);
      C_dominant = std::min(C_dominant, C[j]);
    }
    const double C_cut = hyperbolic ? C_dominant + params_.hyperbolic_row_band : C_dominant;
    for (int j = 0; j < 3; ++j) {
      if (std::isnan(C[j]) || !Accept(C[j])) continue;  // NaN: unlimited hyperbolic axis
      if (hyperbolic && C[j] > C_cut) continue;         // implied by the dominant row
      EmitPerAxis(i, j, bound, C[j]);
    }
  }

  // C of row (j, i): hyperbolic 1 - kappa^j |V'_ji| |s_i - 1| (eqs. 11-12 times kappa^j), NaN
  // for an unlimited axis (C == 1, no row); orthogonal |V'_ji| - |s_i - 1| / |d^j| (eqs. 19-20
  // divided by |d^j|).
  double CalcPerAxisValue(int i, int j, StrainBound bound) const {
    const bool is_max = bound == StrainBound::kMax;
    const double a = std::abs(V_prime_(j, i));
    const double e = std::abs(svd_.s[i] - 1.0);
    if (params_.projection == StrainProjection::kHyperbolic) {
      const double kappa = is_max ? params_.kappa_max[j] : params_.kappa_min[j];
      return kappa == 0.0 ? std::numeric_limits<double>::quiet_NaN() : 1.0 - kappa * a * e;
    }
    const double d = is_max ? params_.d_max_capped[j] : params_.d_min_capped[j];
    return a - e / std::abs(d);
  }

  // Appends row (j, i) with its Jacobian.
  void EmitPerAxis(int i, int j, StrainBound bound, double C) {
    const bool is_max = bound == StrainBound::kMax;
    const double sigma = is_max ? 1.0 : -1.0;  // sign(s_i - 1)
    const double e = svd_.s[i] - 1.0;
    const double w_j = V_prime_(j, i);
    const double a = std::abs(w_j);
    const std::int8_t axis = static_cast<std::int8_t>(j);
    CalcGradients(i);
    if (params_.projection == StrainProjection::kHyperbolic) {
      // dC = -kappa sigma [sgn(V'_ji)(s_i - 1) dV'_ji + |V'_ji| ds_i] (eqs. 17-18).
      const double kappa = is_max ? params_.kappa_max[j] : params_.kappa_min[j];
      Emit(i, axis, bound, C, -kappa * sigma * (Sign(w_j) * e * dw_.row(j).transpose() + a * ds_));
      return;
    }
    // dC = sgn(V'_ji) dV'_ji - sigma ds_i / |d^j|.
    const double d = is_max ? params_.d_max_capped[j] : params_.d_min_capped[j];
    Emit(i, axis, bound, C, Sign(w_j) * dw_.row(j).transpose() - sigma / std::abs(d) * ds_);
  }

  // Linear interpolation (eqs. 21-22): L = ||diag(s^j) w||, delta = |L - 1|,
  // C = 1 - |s_i - 1| / delta.
  void EvaluateLinearInterpolation(int i, StrainBound bound) {
    const bool is_max = bound == StrainBound::kMax;
    const double sigma = is_max ? 1.0 : -1.0;
    const double e = svd_.s[i] - 1.0;
    const Vec3 s_cap = Vec3::Ones() + (is_max ? params_.d_max_capped : params_.d_min_capped);
    const Vec3 weighted = s_cap.cwiseProduct(V_prime_.col(i));
    const double L = weighted.norm();
    const double delta = sigma * (L - 1.0);  // > 0: all capped s^j lie on the bound's side of 1
    const double C = 1.0 - std::abs(e) / delta;
    if (!Accept(C)) return;
    CalcGradients(i);
    // dC = -sigma ds_i / delta + (s_i - 1) dL / delta^2, dL = sum_j s_j^2 w_j dw_j / L.
    Vec12 J = -sigma / delta * ds_;
    if (!SkipFrameTerm(s_cap) && L > 0.0) {
      J += (e / (delta * delta * L)) * (dw_.transpose() * s_cap.cwiseProduct(weighted));
    }
    Emit(i, -1, bound, C, J);
  }

  // Ellipsoid (docs/math.md §3.5): n = ||K w||, C = 1 - |s_i - 1| n.
  void EvaluateEllipsoid(int i, StrainBound bound) {
    const bool is_max = bound == StrainBound::kMax;
    const double sigma = is_max ? 1.0 : -1.0;
    const double e = svd_.s[i] - 1.0;
    const Vec3& kappa = is_max ? params_.kappa_max : params_.kappa_min;
    const Vec3 kw = kappa.cwiseProduct(V_prime_.col(i));
    const double n = kw.norm();
    if (n == 0.0) return;  // only unlimited axes see v_i: C == 1
    const double C = 1.0 - std::abs(e) * n;
    if (!Accept(C)) return;
    CalcGradients(i);
    // dC = -sigma [n ds_i + (s_i - 1) sum_j (kappa_j^2 w_j / n) dV'_ji].
    Vec12 J = -sigma * n * ds_;
    if (!SkipFrameTerm(kappa)) J -= (sigma * e / n) * (dw_.transpose() * kappa.cwiseProduct(kw));
    Emit(i, -1, bound, C, J);
  }

  // Non-inversion floor (docs/math.md §3.8): C = (s_i - f) / (1 - f), dC = ds_i / (1 - f).
  void EvaluateFloor(int i) {
    const double scale = 1.0 / (1.0 - params_.inversion_floor);
    const double C = (svd_.s[i] - params_.inversion_floor) * scale;
    if (!Accept(C)) return;
    CalcGradients(i);
    Emit(i, kStrainFloorAxis, StrainBound::kMin, C, scale * ds_);
  }

  // Tracks min C; true when the row is to be emitted with a Jacobian.
  bool Accept(double C) {
    min_C_ = std::min(min_C_, C);
    return rows_ != nullptr && C < params_.activation_margin;
  }

  // The dV/dx term vanishes identically for equal weights, or is dropped when frozen.
  bool SkipFrameTerm(const Vec3& weights) const {
    return params_.freeze_frame_jacobian || IsIsotropic(weights);
  }

  // ds_i/dx and d(V' e_i)/dx = Q^T dv_i/dx (zero when the frame is frozen), once per i.
  void CalcGradients(int i) {
    if (have_grad_) return;
    have_grad_ = true;
    ds_ = CalcSingularValueGradient(svd_, r_, i);
    const bool need_dv = !params_.freeze_frame_jacobian &&
                         !(params_.projection == StrainProjection::kEllipsoid &&
                           IsIsotropic(params_.kappa_max) && IsIsotropic(params_.kappa_min)) &&
                         !(params_.projection == StrainProjection::kLinearInterpolation &&
                           IsIsotropic(params_.d_max_capped) && IsIsotropic(params_.d_min_capped));
    if (need_dv) {
      dw_.noalias() =
          Q_.transpose() * CalcSingularVectorGradient(svd_, r_, i, params_.svd_gap_epsilon);
    } else {
      dw_.setZero();
    }
  }

  // Appends one row; axis -1 means the per-principal modes, keyed on the matched axis pi(i).
  void Emit(int i, std::int8_t axis, StrainBound bound, double C, const Vec12& J) {
    const std::int8_t m = static_cast<std::int8_t>(match_[i]);
    StrainLimitRow& row = rows_->emplace_back();
    row.J = J;
    row.C = C;
    row.key = StrainLimitKey{element_, axis < 0 ? m : axis, m, bound};
    row.principal_index = static_cast<std::int8_t>(i);
    ++num_emitted_;
  }

  const int element_;
  const TetRestRows& r_;
  const SignedSvd& svd_;
  const Mat3& Q_;
  const StrainLimitParams& params_;
  std::vector<StrainLimitRow>* rows_;
  const Mat3 V_prime_;
  const std::array<int, 3> match_;
  double min_C_ = std::numeric_limits<double>::infinity();
  int num_emitted_ = 0;
  bool have_grad_ = false;
  Vec12 ds_;
  Mat3x12 dw_;
};

}  // namespace

bool StrainLimitKey::operator==(const StrainLimitKey& other) const {
  return element == other.element && axis == other.axis && principal_axis == other.principal_axis &&
         bound == other.bound;
}

std::array<std::int64_t, 4> StrainLimitKey::Fields() const {
  return {element, axis, principal_axis, static_cast<std::int64_t>(bound)};
}

std::uint64_t StrainLimitKey::Pack() const {
  return PackRowKeyPayload(kStrainLimitRowKey, Fields());
}

StrainLimitKey StrainLimitKey::Unpack(std::uint64_t packed) {
  const std::array<std::int64_t, 4> fields = UnpackRowKeyPayload(kStrainLimitRowKey, packed);
  StrainLimitKey key;
  key.element = static_cast<int>(fields[0]);
  key.axis = static_cast<std::int8_t>(fields[1]);
  key.principal_axis = static_cast<std::int8_t>(fields[2]);
  key.bound = static_cast<StrainBound>(fields[3]);
  return key;
}

int FindMatchedPrincipalIndex(const std::array<int, 3>& match, int m) {
  for (int i = 0; i < 3; ++i)
    if (match[i] == m) return i;
  TAUT_ASSERT(false);
  return 0;
}

std::array<int, 3> CalcPrincipalAxisMatch(const Mat3& V_prime) {
  int best = 0;
  double best_score = -1.0;
  for (int p = 0; p < 6; ++p) {
    const auto& perm = kPermutations[p];
    const double score = std::abs(V_prime(perm[0], 0)) + std::abs(V_prime(perm[1], 1)) +
                         std::abs(V_prime(perm[2], 2));
    if (score > best_score) {
      best_score = score;
      best = p;
    }
  }
  return kPermutations[best];
}

int AppendStrainLimitRows(int element, const TetRestRows& r, const SignedSvd& svd, const Mat3& Q,
                          const StrainLimitParams& params, std::vector<StrainLimitRow>* rows) {
  TAUT_ASSERT(rows != nullptr);
  RowEvaluator evaluator(element, r, svd, Q, params, rows);
  evaluator.Run();
  return evaluator.num_emitted();
}

int AppendStrainLimitRows(int element, const TetRestRows& r, const TetPositions& x, const Mat3& Q,
                          const StrainLimitParams& params, std::vector<StrainLimitRow>* rows) {
  const SignedSvd svd = CalcSignedSvd(CalcTetDeformationGradient(r, x));
  return AppendStrainLimitRows(element, r, svd, Q, params, rows);
}

double CalcStrainLimitViolation(const TetRestRows& r, const TetPositions& x, const Mat3& Q,
                                const StrainLimitParams& params) {
  const SignedSvd svd = CalcSignedSvd(CalcTetDeformationGradient(r, x));
  RowEvaluator evaluator(-1, r, svd, Q, params, nullptr);
  return std::max(0.0, -evaluator.Run());
}

double CalcMaterialAxisStrain(const TetRestRows& r, const TetPositions& x, const Vec3& q) {
  return (CalcTetDeformationGradient(r, x) * q).norm() - 1.0;
}

}  // namespace taut
