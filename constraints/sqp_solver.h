// The constrained step: SQP outer loop with the total multiplier, each QP solved by one PGS
// (MATH.md §5). Shared by every row type.
#pragma once

#include <vector>

#include "constraints/constraint_row.h"
#include "constraints/island_body.h"
#include "constraints/active_set_polish.h"
#include "constraints/pgs_solver.h"
#include "constraints/step_stats.h"

namespace taut {

// PGS settings of the QPs: 100 sweeps at most.
inline PgsSettings DefaultPgs() {
  PgsSettings pgs;
  pgs.max_sweeps = 100;
  pgs.tolerance = 1e-4;  // in w units (1/s): C error h * 1e-4, far below the SQP tolerance
  return pgs;
}

// Solver settings (defaults suit interactive use; the report sweeps them).
struct SqpSettings {
  int max_iterations = 10;           // SQP iterations per step (cap), before restoration
  double violation_tolerance = 1e-3; // stop when max(0, -C) <= this (C is a fraction of the limit)
  double contact_tolerance = 1e-5;   // [m] the same for contact and joint rows, whose C is a
                                     // distance (rigid contacts: h times a velocity error)
  double stationarity_tolerance = 1e-2;  // ... and ||A(v - v*) - J^T lambda|| / ||J^T lambda||
  int max_restoration_iterations = 10;  // push-only iterations after the cap while infeasible
  int max_line_search_halvings = 8;  // merit backtracking: alpha = 1, 1/2, ...
  double stalled_step = 0.1;         // feasible and last alpha below this: stop (stalled)
  PgsSettings pgs = DefaultPgs();     // sweeps and tolerance of each QP
  bool polish_active_set = true;     // refine an unconverged PGS answer by active-set solves
  ActiveSetPolishSettings polish;
  bool warm_start = true;            // warm-start lambda from the previous step by row key
};

// Solves min 1/2 (v - v*)^T A (v - v*) s.t. C(x0 + h v) >= 0 for the bodies of one island:
//   for k = 0, 1, ...: rows and J_k at x_k = x0 + h v_k; W = J_k A^-1 J_k^T;
//   q = C(x_k)/h + J_k (v* - v_k); PGS from lambda_k -> lambda_QP; v_QP = v* + A^-1 J_k^T lambda_QP;
//   alpha halved while phi(v_k + alpha (v_QP - v_k)) > phi(v_k) - 1e-4 alpha ||v_QP - v_k||_A^2,
//   phi(v) = 1/2 ||v - v*||_A^2 + rho sum max(0, -C)/h, rho >= 2 max lambda (non-decreasing);
//   v, lambda <- v_k + alpha (QP - k).
// Bilateral rows (joints, attachments) enter with a free multiplier and violation |C|.
// Bodies enter with v = v* (after BeginStep) and leave with the constrained v.
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

 private:
  // Positions x_b of every body at velocities v.
  void CalcPositions(double h, const std::vector<IslandBody*>& bodies, const std::vector<VecX>& v);
  // Rows of every source at the current iterate; returns the largest row violation in units of
  // violation_tolerance (contact and joint rows scaled by violation / contact tolerance).
  double CollectRows(double h, const std::vector<IslandBody*>& bodies,
                     const std::vector<ConstraintSource*>& sources, const SqpSettings& settings);
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
  // J v of a row for per-body velocities v.
  double CalcRowVelocity(const ConstraintRow& row, const std::vector<VecX>& v) const;
  // PGS row descriptions of rows_ (unilateral, or friction on the disk of its normal row).
  void BuildPgsRows();
  // Warm-start multipliers of the current rows from `previous_` (matched by key).
  void WarmStart(const std::vector<std::pair<std::uint64_t, double>>& from);
  // Stores the current rows' multipliers into `to`, sorted by key.
  void StoreMultipliers(std::vector<std::pair<std::uint64_t, double>>& to) const;

  std::vector<ConstraintRow> rows_;
  std::vector<PgsRow> pgs_rows_;
  std::vector<std::vector<int>> body_rows_;  // (num_bodies) rows of each body
  std::vector<MatX> Y_;                      // (num_bodies) 3N x rows of the body
  std::vector<VecX> x_;                      // (num_bodies) positions at the iterate
  MatX W_;
  VecX q_, lambda_, lambda_qp_, w_;
  Eigen::RowVectorXd w_row_;  // one row of W being assembled
  std::vector<VecX> v_k_, v_qp_, v_trial_, dv_;
  VecX scratch_, jt_;  // 3N work vectors (A dv, J^T lambda), reused across steps
  std::vector<std::pair<std::uint64_t, double>> previous_;  // last step's multipliers by key
  std::vector<std::pair<std::uint64_t, double>> iterate_;   // this step's lambda_k by key
};

}  // namespace taut
