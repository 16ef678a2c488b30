// The constrained step: SQP outer loop with the total multiplier, each QP solved by one PGS
// (docs/math.md §5.7). Shared by every row type.
#pragma once

#include <cstdint>
#include <vector>

#include "constraints/active_set_polish.h"
#include "constraints/constraint_row.h"
#include "constraints/curved_dual_metric.h"
#include "constraints/delassus_columns.h"
#include "constraints/island_body.h"
#include "constraints/island_rows.h"
#include "constraints/kkt_certificate.h"
#include "constraints/pgs_solver.h"
#include "constraints/sqp_settings.h"
#include "constraints/step_stats.h"

namespace taut {

// PGS tolerance (w units, 1/s) of a QP at step h: settings.pgs.tolerance, and from the
// warm-start velocity at most warm_stop_distance_factor * contact_tolerance / (2 h), so that one
// QP leaves the distance rows as tight as the warm stop asks (docs/math.md §5.7).
double CalcQpPgsTolerance(double h, bool warm_started, const SqpSettings& settings);

// Solves min 1/2 (v - v*)^T A (v - v*) s.t. C(x0 + h v) >= 0 for the bodies of one island:
//   for k = 0, 1, ...: rows and J_k at x_k = x0 + h v_k; W = J_k A^-1 J_k^T;
//   q = C(x_k)/h + J_k (v* - v_k); PGS from lambda_k -> lambda_QP; v_QP = v* + A^-1 J_k^T
//   lambda_QP; alpha halved while phi(v_k + alpha (v_QP - v_k)) > phi(v_k) - 1e-4 alpha ||v_QP -
//   v_k||_A^2, phi(v) = 1/2 ||v - v*||_A^2 + rho sum max(0, -C)/h, rho >= 2 max lambda
//   (non-decreasing); v, lambda <- v_k + alpha (QP - k).
// Bilateral rows (joints, attachments) enter with a free multiplier and violation |C|.
// Bodies enter with v = v* (after BeginStep) and leave with the constrained v. v_0 = v*, or with
// SqpSettings::warm_start_velocity v* + A^-1 J_0^T lambda_0 (the last step's multipliers on the
// rows at x0), falling back to v* when the solve from there fails (docs/math.md §5.7).
class SqpSolver {
 public:
  // Solves one step of length h for the island `bodies`; fills the constraint part of `stats`.
  void Solve(double h, const std::vector<IslandBody*>& bodies,
             const std::vector<ConstraintSource*>& sources, const SqpSettings& settings,
             StepStats& stats);
  // Same for deformable bodies only (wraps them; allocates, for tests and tools).
  void Solve(double h, const std::vector<DeformableBody*>& bodies,
             const std::vector<ConstraintSource*>& sources, const SqpSettings& settings,
             StepStats& stats);
  // Last step's multipliers by row key (shared with the primal path by IslandSolver).
  KeyedMultipliers& mutable_warm_starts() { return previous_; }
  // The rows of the last Solve, collected at its final velocities, and their multipliers (one per
  // row, the total multiplier lambda_k, or the refitted multipliers that certified the step:
  // CalcKktResidualsWithRefit; contact rows: impulses [N s]). Read-only: forces out.
  const IslandRows& rows() const { return rows_; }
  const VecX& multipliers() const { return reported_; }
  // True when the last Solve stopped infeasible because neither the merit step nor a push-only
  // restoration step lowered anything: the step is locally infeasible (docs/math.md §5.7).
  bool stalled_infeasible() const { return stalled_infeasible_; }

 private:
  // Positions x_b of every body at velocities v (into x_).
  void CalcPositions(double h, const std::vector<IslandBody*>& bodies, const std::vector<VecX>& v);
  // The stages of Solve, in order. Set-up of a solve from v*: sizes, v_k = v*, warm starts.
  void BeginSolve(const std::vector<IslandBody*>& bodies, const SqpSettings& settings);
  // Stage: v_k = v* + A^-1 J_0^T lambda_0, the last step's multipliers (by key) on the rows at the
  // step's start positions x0 (where the last step collected its final rows), when it has any
  // (returns whether v_k moved).
  bool StartFromWarmMultipliers(double h, const std::vector<IslandBody*>& bodies,
                                const std::vector<ConstraintSource*>& sources,
                                const SqpSettings& settings, StepStats& stats);
  // Stage: the SQP iterations from v_k until certified, capped or stalled.
  void Iterate(double h, const std::vector<IslandBody*>& bodies,
               const std::vector<ConstraintSource*>& sources, const SqpSettings& settings,
               StepStats& stats);
  // Rows at x_k = x0 + h v_k (or those a certificate step collected there); returns their
  // largest violation.
  double CollectRowsAtIterate(double h, const std::vector<IslandBody*>& bodies,
                              const std::vector<ConstraintSource*>& sources, double distance_scale,
                              StepStats& stats);
  // The QP at the iterate: W, q = C/h + J (v* - v_k) (restoration: C/h), the PGS rows and the
  // starting lambda_QP.
  void BuildQp(double h, const std::vector<IslandBody*>& bodies, bool restoring);
  // lambda_QP by one PGS (and the active-set polish where PGS left a residual), to
  // CalcQpPgsTolerance.
  void SolveQp(double h, const SqpSettings& settings, StepStats& stats);
  // v_QP from lambda_QP.
  void CalcQpVelocities(const std::vector<IslandBody*>& bodies, bool restoring);
  // Rows at the full QP step v_QP that the QP lacked and v_QP violates join rows_, linearized
  // about v_k (SqpSettings::max_row_discovery_passes); true when any did (solve the QP again).
  bool AddRowsViolatedAtQpStep(double h, const std::vector<IslandBody*>& bodies,
                               const std::vector<ConstraintSource*>& sources, double distance_scale,
                               StepStats& stats);
  // Restoration: v_k, lambda_k pushed towards v_QP as far as the violation drops; false (and
  // v_k kept) when no tried push lowers it.
  bool TakeRestorationStep(double h, const std::vector<IslandBody*>& bodies,
                           const std::vector<ConstraintSource*>& sources,
                           const SqpSettings& settings, StepStats& stats);
  // The merit line search (or certificate step) to the next iterate; returns the step length, 0
  // when no tried step lowers the merit (v_k, lambda_k kept).
  double TakeMeritStep(double h, const std::vector<IslandBody*>& bodies,
                       const std::vector<ConstraintSource*>& sources, const SqpSettings& settings,
                       const KktResiduals& kkt, double& rho, StepStats& stats);
  // Y_b = A_b^-1 J_b^T per body and W = J Y.
  void BuildDelassus(const std::vector<IslandBody*>& bodies);
  // Sum of violations of every source at velocities v (per body).
  double CalcViolationSum(double h, const std::vector<IslandBody*>& bodies,
                          const std::vector<ConstraintSource*>& sources,
                          const std::vector<VecX>& v);
  // Merit phi at velocities v (per body) with penalty weight rho.
  double CalcMerit(double h, const std::vector<IslandBody*>& bodies,
                   const std::vector<ConstraintSource*>& sources, const std::vector<VecX>& v,
                   double rho);
  // The certificate of the full QP step (v_QP, lambda_QP) at its own rows (collected at
  // x_k + h v_QP, the multipliers matched by key).
  KktResiduals CalcFullStepCertificate(double h, const std::vector<IslandBody*>& bodies,
                                       const std::vector<ConstraintSource*>& sources,
                                       const SqpSettings& settings, StepStats& stats);
  // Distance rows (contacts, joints) of `kkt` within warm_stop_distance_factor of their tolerance.
  static bool HasTightDistanceRows(const KktResiduals& kkt, const SqpSettings& settings);
  // The full QP step's certificate passes with its distance rows within
  // warm_stop_distance_factor of their tolerance: the iterate the SQP stops at.
  static bool IsCertifiedWithTightRows(const KktResiduals& full, const SqpSettings& settings);
  // True when the full QP step may be taken although the merit rejects it
  // (SqpSettings::certificate_steps): its certificate `full`'s residual is below 0.9 x
  // `residual` and its worst violation below max(`violation`, full_step_violation_factor x
  // tolerance).
  static bool AcceptsFullStepResidual(const KktResiduals& full, const SqpSettings& settings,
                                      double residual, double violation);
  // (v_k, lambda_k) <- (v_QP, lambda_QP), the rows at v_QP kept for the next iteration.
  void TakeFullStep();

  IslandRows rows_;
  std::vector<PgsRow> pgs_rows_;
  DelassusColumns columns_;  // Y_b = A_b^-1 J_b^T per body
  std::vector<VecX> x_;      // (num_bodies) positions at a trial velocity
  MatX W_;
  VecX q_, lambda_, lambda_qp_, w_;
  VecX reported_;          // the multipliers of the last certificate (multipliers())
  int num_collected_ = 0;  // rows_ collected at v_k; look-ahead rows follow
  std::vector<std::uint64_t> look_ahead_keys_;       // their keys, sorted
  std::vector<std::uint64_t> next_look_ahead_keys_;  // the next pass's (scratch)
  IslandRows full_rows_;                             // rows at the full QP step
  double full_violation_ = 0.0;     // their largest violation (IslandRows::Collect)
  bool full_rows_at_v_k_ = false;   // a full step was taken: full_rows_ are v_k's rows
  bool full_rows_at_v_qp_ = false;  // full_rows_ were collected at the current v_QP
  VecX full_lambda_;                // lambda_QP on full_rows_
  KeyedMultipliers qp_keyed_;       // lambda_QP by key
  std::vector<VecX> v_k_, v_qp_, v_trial_, dv_;
  VecX scratch_, jt_;                // 3N work vectors (A dv, J^T lambda), reused across steps
  std::vector<VecX> a_dv_;           // A (v_k - v*) per body at the last certificate
  KeyedMultipliers previous_;        // last step's multipliers by key
  bool stalled_infeasible_ = false;  // see stalled_infeasible()
  KeyedMultipliers iterate_;         // this step's lambda_k by key
  bool warm_started_ = false;        // this Iterate starts from the warm-start velocity
  // SqpSettings::dual_curvature: the QP of this iteration in the metric N = A + G.
  CurvedDualMetric metric_;
  bool metric_on_ = false;
  std::vector<VecX> v_free_;  // the QP's free velocity: v*, or v_k - N^-1 A (v_k - v*)
};

}  // namespace taut
