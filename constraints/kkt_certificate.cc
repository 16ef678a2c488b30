#include "constraints/kkt_certificate.h"

#include <algorithm>
#include <cmath>

#include "constraints/limit_multiplier_refit.h"

namespace taut {

double KktResiduals::max_primal() const { return *std::max_element(primal.begin(), primal.end()); }

double KktResiduals::max_complementarity() const {
  return *std::max_element(complementarity.begin(), complementarity.end());
}

double KktResiduals::max_distance_residual() const {
  double residual = 0.0;
  for (int i = 0; i < kNumRowTypes; ++i)
    if (!kRowTypes[i].is_limit) residual = std::max({residual, primal[i], complementarity[i]});
  return residual;
}

bool KktResiduals::IsFeasible(double violation_tolerance) const {
  return max_primal() <= violation_tolerance && max_complementarity() <= violation_tolerance;
}

bool IsCertified(const KktResiduals& kkt, double violation_tolerance,
                 double stationarity_tolerance) {
  return kkt.IsFeasible(violation_tolerance) && kkt.dual <= 1e-6 &&
         kkt.stationarity <= stationarity_tolerance;
}

double CalcCertificateResidual(const KktResiduals& kkt, double violation_tolerance,
                               double stationarity_tolerance) {
  return std::max(std::max(kkt.max_primal(), kkt.max_complementarity()) / violation_tolerance,
                  kkt.stationarity / stationarity_tolerance);
}

void RecordKkt(const KktResiduals& kkt, StepStats& stats) {
  stats.stationarity = kkt.stationarity;
  stats.kkt_primal = kkt.max_primal();
  stats.kkt_complementarity = kkt.max_complementarity();
  stats.kkt_dual = kkt.dual;
  for (int i = 0; i < kNumRowTypes; ++i) {
    stats.kkt_primal_by_type[i] = kkt.primal[i];
    stats.kkt_complementarity_by_type[i] = kkt.complementarity[i];
  }
}

namespace {

// Adds body b's terms of stationarity: ||A(v - v*) - J^T lambda||^2, ||J^T lambda||^2 and
// ||A(v - v*)||^2 over its free blocks (pinned blocks carry reaction forces: A v is 0 there).
// jt: work vector (J^T lambda), one per certificate rather than per body.
void AddStationarityTerms(const IslandBody& body, int b, const IslandRows& rows, const VecX& lambda,
                          const VecX& a_dv, VecX& jt, double& residual, double& force,
                          double& momentum) {
  jt.setZero(a_dv.size());
  for (int c : rows.body_rows(b))
    rows[c].ForEachEntry([&](int on, int block, const Vec3& J) {
      if (on == b) jt.segment<3>(3 * block) += lambda[c] * J;
    });
  for (int i = 0; i < body.num_blocks(); ++i)
    if (!body.is_free_block(i)) jt.segment<3>(3 * i).setZero();
  residual += (a_dv - jt).squaredNorm();
  force += jt.squaredNorm();
  momentum += a_dv.squaredNorm();
}

// Relative to the larger of the two sides, so a velocity change without a constraint force
// counts as fully non-stationary (1) whatever the body's mass.
double StationarityFromTerms(double residual, double force, double momentum) {
  const double scale = std::max(force, momentum);
  return scale > 0.0 ? std::sqrt(residual / scale) : 0.0;
}

}  // namespace

void CalcVelocityChangeMomentum(const std::vector<IslandBody*>& bodies, const std::vector<VecX>& v,
                                std::vector<VecX>& a_dv) {
  a_dv.resize(bodies.size());
  for (size_t b = 0; b < bodies.size(); ++b)
    bodies[b]->ApplySystemMatrix(v[b] - bodies[b]->v_star(), a_dv[b]);
}

double CalcStationarity(const std::vector<IslandBody*>& bodies, const IslandRows& rows,
                        const VecX& lambda, const std::vector<VecX>& v, VecX& scratch) {
  double residual = 0.0, force = 0.0, momentum = 0.0;
  VecX jt;
  for (size_t b = 0; b < bodies.size(); ++b) {
    bodies[b]->ApplySystemMatrix(v[b] - bodies[b]->v_star(), scratch);
    AddStationarityTerms(*bodies[b], static_cast<int>(b), rows, lambda, scratch, jt, residual,
                         force, momentum);
  }
  return StationarityFromTerms(residual, force, momentum);
}

double CalcStationarity(const std::vector<IslandBody*>& bodies, const IslandRows& rows,
                        const VecX& lambda, const std::vector<VecX>& a_dv) {
  double residual = 0.0, force = 0.0, momentum = 0.0;
  VecX jt;
  for (size_t b = 0; b < bodies.size(); ++b)
    AddStationarityTerms(*bodies[b], static_cast<int>(b), rows, lambda, a_dv[b], jt, residual,
                         force, momentum);
  return StationarityFromTerms(residual, force, momentum);
}

namespace {

// Every residual of (v, lambda) but stationarity.
KktResiduals CalcRowResiduals(const IslandRows& rows, const VecX& lambda,
                              const std::vector<VecX>& v, double h, double distance_scale) {
  KktResiduals kkt;
  const double lambda_scale = lambda.size() > 0 ? lambda.cwiseAbs().maxCoeff() : 0.0;
  const double active = 1e-9 * lambda_scale;  // lambda above this counts as pushing
  double dual = 0.0;
  for (int c = 0; c < rows.size(); ++c) {
    const ConstraintRow& row = rows[c];
    const int type = static_cast<int>(row.type);
    const double scale = CalcLimitUnitScale(row, distance_scale);
    kkt.primal[type] = std::max(kkt.primal[type], row.violation() * scale);
    if (row.friction_of > 0) {
      // Disk |lambda_t| <= mu lambda_n (checked once per pair, on its first row).
      const int normal = c - row.friction_of;
      const int first = normal + 1;
      const double radius = row.mu * std::max(0.0, lambda[normal]);
      const double norm_t = std::hypot(lambda[first], lambda[first + 1]);
      if (row.friction_of == 1) dual = std::max(dual, norm_t - radius);
      if (norm_t < radius * (1.0 - 1e-6) - active)
        kkt.complementarity[type] =
            std::max(kkt.complementarity[type], h * std::abs(rows.CalcRowVelocity(c, v)) * scale);
    } else if (row.bilateral) {
      dual = std::max({dual, row.lo - lambda[c], lambda[c] - row.hi});
    } else {
      dual = std::max(dual, -lambda[c]);
      if (lambda[c] > active)
        kkt.complementarity[type] = std::max(kkt.complementarity[type], std::abs(row.C) * scale);
    }
  }
  kkt.dual = lambda_scale > 0.0 ? std::max(0.0, dual) / lambda_scale : 0.0;
  return kkt;
}

}  // namespace

KktResiduals CalcKktResiduals(const std::vector<IslandBody*>& bodies, const IslandRows& rows,
                              const VecX& lambda, const std::vector<VecX>& v, double h,
                              double distance_scale, VecX& scratch) {
  KktResiduals kkt = CalcRowResiduals(rows, lambda, v, h, distance_scale);
  kkt.stationarity = CalcStationarity(bodies, rows, lambda, v, scratch);
  return kkt;
}

KktResiduals CalcKktResiduals(const std::vector<IslandBody*>& bodies, const IslandRows& rows,
                              const VecX& lambda, const std::vector<VecX>& v, double h,
                              double distance_scale, const std::vector<VecX>& a_dv) {
  KktResiduals kkt = CalcRowResiduals(rows, lambda, v, h, distance_scale);
  kkt.stationarity = CalcStationarity(bodies, rows, lambda, a_dv);
  return kkt;
}

namespace {

// Relative band below the rim of a Coulomb disk within which a sliding pair's force counts as the
// rim's (FitFrictionToCurrentDisks).
constexpr double kRimBand = 1e-2;

// lambda's friction pairs rescaled onto the rim of the disk of radius mu max(0, lambda_n) of
// their normal multiplier: pairs outside it, and pairs sliding (a row with h |J_t v| above the
// tolerance in limit units) within kRimBand below it; a sliding pair only if its force opposes its
// slip. Returns false when no pair moved.
bool FitFrictionToCurrentDisks(const IslandRows& rows, const std::vector<VecX>& v, double h,
                               double distance_scale, double violation_tolerance, VecX& lambda) {
  bool moved = false;
  for (int c = 0; c < rows.size(); ++c) {
    const ConstraintRow& row = rows[c];
    if (row.friction_of != 1) continue;
    const double radius = row.mu * std::max(0.0, lambda[c - 1]);
    const double norm_t = std::hypot(lambda[c], lambda[c + 1]);
    if (norm_t == radius || norm_t == 0.0) continue;
    const double u1 = rows.CalcRowVelocity(c, v), u2 = rows.CalcRowVelocity(c + 1, v);
    const double slip = h * std::max(std::abs(u1), std::abs(u2));
    // On the rim a sliding contact's force must oppose its slip (Coulomb's direction); inside
    // the disk only a sliding pair within kRimBand of the rim moves onto it.
    const bool sliding = slip * distance_scale > violation_tolerance;
    if (sliding && !(lambda[c] * u1 + lambda[c + 1] * u2 < 0.0)) continue;
    if (norm_t < radius && !(sliding && norm_t >= (1.0 - kRimBand) * radius)) continue;
    const double scale = radius / norm_t;
    lambda[c] *= scale;
    lambda[c + 1] *= scale;
    moved = true;
  }
  return moved;
}

}  // namespace

KktResiduals CalcKktResidualsWithRefit(const std::vector<IslandBody*>& bodies,
                                       const IslandRows& rows, const VecX& lambda,
                                       const std::vector<VecX>& v, double h, double distance_scale,
                                       double violation_tolerance, double stationarity_tolerance,
                                       std::vector<VecX>& a_dv, VecX& certified,
                                       bool a_dv_current) {
  certified = lambda;
  if (!a_dv_current) CalcVelocityChangeMomentum(bodies, v, a_dv);
  const KktResiduals kkt = CalcKktResiduals(bodies, rows, lambda, v, h, distance_scale, a_dv);
  if (IsCertified(kkt, violation_tolerance, stationarity_tolerance)) return kkt;
  // Friction forces just off the rims of their Coulomb disks (the primal path projects them onto
  // the disks of the previous normal multipliers, which the update moves): the refit starts from
  // the same forces on the rims of the current ones (docs/math.md §5.10).
  KktResiduals start = kkt;
  if (FitFrictionToCurrentDisks(rows, v, h, distance_scale, violation_tolerance, certified)) {
    start = CalcKktResiduals(bodies, rows, certified, v, h, distance_scale, a_dv);
    if (IsCertified(start, violation_tolerance, stationarity_tolerance)) return start;
  }
  if (start.max_primal() > violation_tolerance || start.dual > 1e-6) {
    certified = lambda;
    return kkt;
  }
  // Aim below the tolerance: the refit stops once stationarity is surely within half of it.
  RefitLimitMultipliers(bodies, rows, a_dv, violation_tolerance, 0.5 * stationarity_tolerance,
                        kRefitSweeps, certified);
  const KktResiduals kkt_refit =
      CalcKktResiduals(bodies, rows, certified, v, h, distance_scale, a_dv);
  if (IsCertified(kkt_refit, violation_tolerance, stationarity_tolerance)) return kkt_refit;
  certified = lambda;
  return kkt;
}

}  // namespace taut
