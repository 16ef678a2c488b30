// Convergence certificate of a constrained step (both island solvers): the KKT residuals of
//   min 1/2 ||v - v*||_A^2  s.t.  C(x0 + h v) >= 0 (bilateral: = 0), friction on the Coulomb disk,
// at the solver's final iterate (v, lambda) with the rows linearized there (docs/math.md §5.10).
#pragma once

#include <array>
#include <vector>

#include "constraints/island_rows.h"

namespace taut {

// Residuals at an iterate. Distance rows (contacts, joints) count in limit-row units, i.e. times
// violation_tolerance / contact_tolerance, so one tolerance applies to every row.
struct KktResiduals {
  // max(0, -C) (bilateral |C|) per row type.
  std::array<double, kNumRowTypes> primal{};
  // Unilateral rows with lambda > 0: |C| (the row must be at its bound); friction rows inside the
  // disk: h |J_t v| (sticking contacts must not slide). Per row type.
  std::array<double, kNumRowTypes> complementarity{};
  // Distance of lambda from its set (lambda >= 0; [lo, hi]; |lambda_t| <= mu lambda_n) relative to
  // max |lambda|.
  double dual = 0.0;
  // ||A(v - v*) - J^T lambda|| / max(||J^T lambda||, ||A(v - v*)||) on free blocks.
  double stationarity = 0.0;
  // Primal and complementarity within tolerance (stationarity and dual aside).
  bool IsFeasible(double violation_tolerance) const;

  double max_primal() const;
  double max_complementarity() const;
  // The largest primal or complementarity residual of the distance rows (contacts, joints; in
  // limit-row units), 0 without such rows.
  double max_distance_residual() const;
};

// Residuals of `rows` (collected at v) with multipliers lambda. `scratch` is a work vector.
KktResiduals CalcKktResiduals(const std::vector<IslandBody*>& bodies, const IslandRows& rows,
                              const VecX& lambda, const std::vector<VecX>& v, double h,
                              double distance_scale, VecX& scratch);
// The same with a_dv = A (v - v*) per body given (CalcVelocityChangeMomentum at the same v).
KktResiduals CalcKktResiduals(const std::vector<IslandBody*>& bodies, const IslandRows& rows,
                              const VecX& lambda, const std::vector<VecX>& v, double h,
                              double distance_scale, const std::vector<VecX>& a_dv);

// a_dv[b] = A_b (v_b - v*_b) for every body: the momentum side of stationarity, one product with
// each body's system matrix. A certificate computes it once for all the multipliers it tries.
void CalcVelocityChangeMomentum(const std::vector<IslandBody*>& bodies, const std::vector<VecX>& v,
                                std::vector<VecX>& a_dv);

// The residuals of (v, lambda), or, when v is primal and lambda dual feasible but the pair fails
// the certificate (complementarity or stationarity), those of (v, lambda_fit) if they pass, with
// lambda_fit the limit rows' least-squares multipliers at v (constraints/limit_multiplier_refit.h):
// the certificate asks only that SOME multipliers satisfy the KKT conditions with v. `certified`
// <- the multipliers whose residuals are returned (the forces a solver reports, and the primal
// path's next warm start on rows at their bounds; docs/math.md §5.10, refitted multipliers).
// a_dv <- A (v - v*) per body (CalcVelocityChangeMomentum): one product per body, shared by every
// multiplier vector tried; none when the caller says a_dv holds it already (a_dv_current).
KktResiduals CalcKktResidualsWithRefit(const std::vector<IslandBody*>& bodies,
                                       const IslandRows& rows, const VecX& lambda,
                                       const std::vector<VecX>& v, double h, double distance_scale,
                                       double violation_tolerance, double stationarity_tolerance,
                                       std::vector<VecX>& a_dv, VecX& certified,
                                       bool a_dv_current = false);
// Sweeps of that refit (a sweep costs about one pass over the rows' Jacobians).
inline constexpr int kRefitSweeps = 50;

// The certificate's residual as one number: the larger of max(primal, complementarity) over the
// violation tolerance and the stationarity over its tolerance (<= 1: primal, complementarity and
// stationarity certified).
double CalcCertificateResidual(const KktResiduals& kkt, double violation_tolerance,
                               double stationarity_tolerance);

// True when every residual is within tolerance: primal and complementarity <= violation_tolerance
// (C units), dual <= 1e-6, stationarity <= stationarity_tolerance.
bool IsCertified(const KktResiduals& kkt, double violation_tolerance,
                 double stationarity_tolerance);

// Writes the residuals into the step's statistics (kkt_*, stationarity).
void RecordKkt(const KktResiduals& kkt, StepStats& stats);

// ||A(v - v*) - J^T lambda|| / max(||J^T lambda||, ||A(v - v*)||) over the free blocks of every
// body (0 when both sides vanish).
double CalcStationarity(const std::vector<IslandBody*>& bodies, const IslandRows& rows,
                        const VecX& lambda, const std::vector<VecX>& v, VecX& scratch);
// The same with a_dv = A (v - v*) per body given.
double CalcStationarity(const std::vector<IslandBody*>& bodies, const IslandRows& rows,
                        const VecX& lambda, const std::vector<VecX>& a_dv);

}  // namespace taut
