#include "constraints/strain_limit_source.h"

#include <algorithm>
#include <cmath>

#include "constraints/strain_frame_curvature.h"
#include "constraints/strain_limit_curvature.h"
#include "plugin/tet_rest_data.h"

namespace taut {

namespace {
const TetElementModel& AsTets(const DeformableBody& body) {
  const TetElementModel* tets = body.model().tet_model();
  TAUT_DEMAND(tets != nullptr, "body '", body.name(),
              "': strain limits need a tet body (co-rotational tetrahedra)");
  return *tets;
}
}  // namespace

StrainLimitSource::StrainLimitSource(const DeformableBody& body,
                                     const StrainLimitSettings& settings, int source_id)
    : body_(body), tets_(AsTets(body)), settings_(settings), key_(kStrainLimitRowKey, source_id) {
  settings_.Validate(tets_.num_elements(), "body '" + body.name() + "' strain limits");
  params_ = CalcStrainLimitParams(settings_);
  full_curvature_ = HasStrainFrameCurvature(params_);
  exact_curvature_ = HasExactStrainCurvature(params_);
  // Hyperbolic and ellipsoid rows bound their C by the stretches alone (CalcStretchBand): rows
  // are emitted below C = tau (the activation band), a violation needs C < 0 (tau = 0).
  const double tau = params_.activation_margin;
  screen_ = (params_.projection == StrainProjection::kHyperbolic ||
             params_.projection == StrainProjection::kEllipsoid) &&
            std::isfinite(tau) && tau < 1.0;
  if (screen_) {
    active_band_ = CalcStretchBand(tau);
    violation_band_ = CalcStretchBand(0.0);
  }
}

StrainLimitSource::StretchBand StrainLimitSource::CalcStretchBand(double tau) const {
  // Every row of principal axis i has C >= 1 - max_j kappa^j |s_i - 1| (kappa_eff <= max_j kappa^j:
  // |V'_ji| <= 1, ||K w|| <= max kappa), so C > tau inside the band;
  // floor rows C = (s_i - f) / (1 - f) exceed tau above s_i = f + tau (1 - f) (docs/math.md §3.8).
  const double slack = 1.0 - tau;
  StretchBand band;
  band.hi = params_.has_max ? 1.0 + slack / params_.kappa_max.maxCoeff() : HUGE_VAL;
  band.lo = params_.has_min ? 1.0 - slack / params_.kappa_min.maxCoeff() : 0.0;
  if (params_.inversion_floor > 0.0) {
    const double f = params_.inversion_floor;
    band.lo = std::max(band.lo, f + tau * (1.0 - f));
  }
  band.lo = std::max(band.lo, 0.0);
  return band;
}

namespace {
// True when the symmetric 3x3 M is positive definite: its leading principal minors are positive
// (Sylvester's criterion).
bool IsPositiveDefinite(const Mat3& M) {
  const double minor2 = M(0, 0) * M(1, 1) - M(0, 1) * M(0, 1);
  return M(0, 0) > 0.0 && minor2 > 0.0 && M.determinant() > 0.0;
}
}  // namespace

bool StrainLimitSource::IsSurelyInside(const std::array<Vec3, 4>& xe, int e,
                                       const StretchBand& band) const {
  if (!screen_) return false;
  // The principal stretches are the square roots of the eigenvalues of F^T F, so all of them lie
  // in (lo, hi) exactly when F^T F - lo^2 I and hi^2 I - F^T F are positive definite; a
  // non-positive det F (inverted: s_3 <= 0) is never inside.
  const Mat3 F = CalcTetDeformationGradient(tets_.rest().elements[e], xe);
  if (!(F.determinant() > 0.0)) return false;
  const Mat3 c = F.transpose() * F;
  if (std::isfinite(band.hi) && !IsPositiveDefinite(band.hi * band.hi * Mat3::Identity() - c))
    return false;
  return IsPositiveDefinite(c - band.lo * band.lo * Mat3::Identity());
}

int StrainLimitSource::AppendRows(const VecX& x, int body_index, std::vector<ConstraintRow>& rows) {
  const int before = static_cast<int>(rows.size());
  for (int e = 0; e < tets_.num_elements(); ++e) {
    element_rows_.clear();
    const auto xe = tets_.GatherElement(x, e);
    if (IsSurelyInside(xe, e, active_band_)) continue;
    const TetRestRows& r = tets_.rest().elements[e].r;
    const SignedSvd& svd = RememberSvd(e, xe, CalcSignedSvd(CalcTetDeformationGradient(r, xe)));
    if (AppendStrainLimitRows(e, r, svd, SelectStrainLimitFrame(settings_, e), params_,
                              &element_rows_) == 0)
      continue;
    const int* nodes = tets_.element_nodes(e);
    for (const StrainLimitRow& r : element_rows_) {
      ConstraintRow& row = rows.emplace_back();
      row.key = key_.PackFields(r.key.Fields());
      row.C = r.C;
      row.body = body_index;
      row.element = e;
      row.type = RowType::kStrainLimit;
      row.full_curvature = full_curvature_;
      row.exact_curvature = exact_curvature_;
      row.num_nodes = 4;
      for (int n = 0; n < 4; ++n) {
        row.nodes[n] = nodes[n];
        row.J[n] = r.J.segment<3>(3 * n);
      }
    }
  }
  return static_cast<int>(rows.size()) - before;
}

void StrainLimitSource::AddIslandCurvature(const IslandIterate& iterate, const ConstraintRow* rows,
                                           const double* weights, int count,
                                           CurvatureSink& sink) const {
  // Rows of one element are adjacent: one SVD per element, and sum_c w_c H_c of its rows is
  // scattered once (16 node blocks per element, not per row). Frame-dependent rows sum their
  // full curvature over vec(P) and clamp the element's sum once (docs/math.md §5.9); the others
  // clamp each row's stretch term (§5.9).
  int element = -1, body = -1;
  SignedSvd svd;
  Mat12 sum = Mat12::Zero();
  Mat9 principal_sum = Mat9::Zero();
  const auto flush = [&] {
    if (element < 0) return;
    if (full_curvature_) {
      sum = MapPrincipalHessianToTet(
          ClampNegativeModes(principal_sum, kFrameCurvatureKeptNegativeFraction), svd,
          tets_.rest().elements[element].r);
    }
    sink.AddElementBlock(body, element, tets_.element_nodes(element), sum);
  };
  for (int c = 0; c < count; ++c) {
    const ConstraintRow& row = rows[c];
    if (!key_.Owns(row.key) || !(weights[c] > 0.0)) continue;
    const StrainLimitKey key = StrainLimitKey::Unpack(RowKeyPayload(row.key));
    const TetRestRows& r = tets_.rest().elements[key.element].r;
    if (key.element != element || row.body != body) {
      flush();
      element = key.element;
      body = row.body;
      sum.setZero();
      principal_sum.setZero();
      svd = FindOrCalcSvd(element, tets_.GatherElement(iterate.x(row.body), element));
    }
    const Mat3& Q = SelectStrainLimitFrame(settings_, element);
    if (full_curvature_) {
      principal_sum.noalias() += weights[c] * CalcPrincipalStrainRowCurvature(svd, Q, params_, key);
    } else {
      sum.noalias() += weights[c] * CalcStrainLimitRowCurvature(r, svd, Q, params_, key);
    }
  }
  flush();
}

const SignedSvd& StrainLimitSource::RememberSvd(int e, const TetPositions& xe,
                                                const SignedSvd& svd) {
  if (svd_cache_.size() != static_cast<size_t>(tets_.num_elements()))
    svd_cache_.assign(tets_.num_elements(), CachedSvd{});
  CachedSvd& entry = svd_cache_[e];
  entry.x = xe;
  entry.svd = svd;
  entry.valid = true;
  return entry.svd;
}

SignedSvd StrainLimitSource::FindOrCalcSvd(int e, const TetPositions& xe) const {
  // The curvature is evaluated at the positions of the last row collection: the same xe, so the
  // same SVD, bit for bit.
  if (static_cast<size_t>(e) < svd_cache_.size() && svd_cache_[e].valid && svd_cache_[e].x == xe)
    return svd_cache_[e].svd;
  return CalcSignedSvd(CalcTetDeformationGradient(tets_.rest().elements[e].r, xe));
}

double StrainLimitSource::CalcElementViolation(const VecX& x, int e) const {
  const auto xe = tets_.GatherElement(x, e);
  if (IsSurelyInside(xe, e, violation_band_)) return 0.0;
  return CalcStrainLimitViolation(tets_.rest().elements[e].r, xe,
                                  SelectStrainLimitFrame(settings_, e), params_);
}

double StrainLimitSource::CalcMaxViolation(const VecX& x) const {
  double violation = 0.0;
  for (int e = 0; e < tets_.num_elements(); ++e)
    violation = std::max(violation, CalcElementViolation(x, e));
  return violation;
}

double StrainLimitSource::CalcViolationSum(const VecX& x) const {
  double sum = 0.0;
  for (int e = 0; e < tets_.num_elements(); ++e) sum += CalcElementViolation(x, e);
  return sum;
}

double StrainLimitSource::CalcMaxAxisStrain(const VecX& x, int axis) const {
  double strain = -1.0;
  for (int e = 0; e < tets_.num_elements(); ++e) {
    const Vec3 q = SelectStrainLimitFrame(settings_, e).col(axis);
    strain = std::max(
        strain, CalcMaterialAxisStrain(tets_.rest().elements[e].r, tets_.GatherElement(x, e), q));
  }
  return strain;
}

}  // namespace taut
