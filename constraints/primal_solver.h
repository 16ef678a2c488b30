// The primal island solver (docs/math.md §5.8): an augmented-Lagrangian
// SQP on the island's velocities, each linearized problem minimized by Newton's method with an
// exact line search, the multipliers updated by projection. Used where the papers' dual PGS
// cannot converge: more limit rows than free DOFs make W = J A^-1 J^T rank-deficient, while the
// primal Newton matrix A + G + sum rho J^T D J stays positive definite for any redundancy.
#pragma once

#include <array>
#include <vector>

#include "constraints/curvature_metric.h"
#include "constraints/island_rows.h"
#include "constraints/kkt_certificate.h"
#include "constraints/sqp_settings.h"

namespace taut {

// Solves min 1/2 ||v - v*||_A^2  s.t.  C(x0 + h v) >= 0 (bilateral: = 0, friction on the disk)
// by the method of multipliers on the augmented Lagrangian
//   Phi(v) = 1/2 ||v - v*||_A^2 + sum_c P_c(y_c(v)) / rho_c,   y_c = lambda_bar_c - rho_c g_c(v),
//   g_c = C_c(x0 + h v)/h (friction: g = J_t v), P_c(y) = integral of Proj_c (1/2 max(0, y)^2 for
//   unilateral rows; Huber-like for intervals [lo, hi] and the disk |y| <= mu lambda_bar_n):
//   for k = 0, 1, ...: minimize Phi over v by Newton: rows, C, J at v; lambda_c = Proj_c(y_c);
//       grad = A(v - v*) - J^T lambda;  H = A + sum rho_c J_c^T D_c J_c + G  (D = dProj/dy,
//       G = h sum lambda_c [-d^2 C_c/dx^2]_+ the row curvature with negative modes clamped);
//       d = -H^-1 grad; alpha from the exact line search of the linearized model, backtracked
//       (Armijo) on the nonlinear Phi;
//     then lambda_bar_c <- Proj_c(y_c(v)),
//   until the KKT residuals at (v, lambda_bar) are within tolerance
//   (constraints/kkt_certificate.h).
// rho_c = penalty_scale / w_c with w_c = sum_i J_ci^T M_i^-1 J_ci (a diagonal Delassus estimate
// from lumped masses; no W is formed), for limit rows kept by key within a multiplier iteration.
// Rows local to one body (strain, energy, node contact) keep H on A's sparsity pattern: one
// sparse factorization per Newton iteration. Rows that couple two bodies (rigid contacts, joints,
// deformable-deformable) enter H matrix-free and the step is solved by PCG preconditioned with
// the per-body factors.
class PrimalSolver {
 public:
  // One step h for the island `bodies` (entered with v = v*, left with the constrained v).
  // `warm` holds the multipliers by row key from the previous step (read and rewritten).
  void Solve(double h, const std::vector<IslandBody*>& bodies,
             const std::vector<ConstraintSource*>& sources, const SqpSettings& settings,
             KeyedMultipliers& warm, StepStats& stats);
  // The rows of the last Solve at its final velocities and their multipliers (one per row;
  // contact rows: impulses [N s]): lambda_bar, or the refitted multipliers that certified the
  // step (CalcKktResidualsWithRefit). Read-only: forces out.
  const IslandRows& rows() const { return rows_; }
  // True when the last PCG with a kept factor ran past its budget: the next Newton matrix is
  // factored afresh, also when that is in the next step (a coupled island's PCG is not capped by
  // the budget, so a poor kept factor would otherwise cost every step; saved by world snapshots
  // through IslandSolver::State).
  bool refactor_next() const { return refactor_next_; }
  void set_refactor_next(bool refactor) { refactor_next_ = refactor; }
  const VecX& multipliers() const { return reported_; }

 private:
  // Stage: rows, C and J at v (into rows_), lambda_bar by key, penalties, linearization.
  void CollectRowsAt(double h, const std::vector<IslandBody*>& bodies,
                     const std::vector<ConstraintSource*>& sources, const std::vector<VecX>& v,
                     const SqpSettings& settings, StepStats& stats);
  // Stage, at an iterate without rows: the minimizer there is v* (H = A), so the iterate moves
  // to v* and collects its rows (a start candidate or a Newton step inside every margin would
  // otherwise end the step away from v*). False when already at v* or v* has no rows: done.
  bool MoveToUnconstrainedVelocity(double h, const std::vector<IslandBody*>& bodies,
                                   const std::vector<ConstraintSource*>& sources,
                                   const SqpSettings& settings, StepStats& stats);
  // Stage: the start of the Newton iterations, the candidate velocity of least Phi (v*, the
  // step-start velocity, the warm start below when Phi of the rows of v* linearized there ranks
  // it first); leaves its rows collected.
  void ChooseStartVelocities(double h, const std::vector<IslandBody*>& bodies,
                             const std::vector<ConstraintSource*>& sources,
                             const SqpSettings& settings, StepStats& stats);
  // v = v* + A^-1 J^T lambda_bar into v_trial_ (false when there is no warm multiplier).
  bool WarmStartVelocities(const std::vector<IslandBody*>& bodies);
  // Whether the last Newton step, taken from a violation of violation_before, shows the inner
  // minimizer violated (PrimalSettings::newton_stall_fraction): the Newton loop ends.
  bool IsViolationStalled(double violation_before, double tolerance,
                          const PrimalSettings& settings) const;
  // rho_c of every row from the diagonal Delassus estimate (friction rows: their normal's), with
  // a pushing limit row's own curvature in its effective mass.
  void CalcPenalties(double h, const std::vector<IslandBody*>& bodies,
                     const PrimalSettings& settings);
  // Keeps the limit rows' rho by key for the Newton iterations and line-search trials of one
  // multiplier iteration, so grad Phi is the gradient of the Phi the line search measures
  // (docs/math.md §5.8, penalties).
  void KeepPenalties();
  // Lowers every rho above max(max_penalty_growth, late_max_penalty_growth) times the row's
  // Delassus value at its current J to that bound and keeps the result (KeepPenalties); returns
  // whether any rho changed. For a Newton matrix that does not factor without curvature.
  bool CapKeptPenalties(const PrimalSettings& settings);
  // Stage: rho of limit rows whose violation stalls over a multiplier iteration grows
  // (PrimalSettings::penalty_growth, capped by the late cap from late_growth_iteration on), applied
  // to the kept penalties before KeepPenalties; `iteration` is the multiplier iteration k.
  void GrowStalledPenalties(const PrimalSettings& settings, double tolerance, int iteration);
  // g0_c with g_c(v + dv) = g0_c + J_c (v + dv) at the collected rows, and which rows H can hold
  // on the bodies' patterns.
  void LinearizeRows(double h, const std::vector<IslandBody*>& bodies);
  // Stage: G = h sum lambda_c [-d^2 C_c]_+ as node blocks, from the sources of limit rows.
  void CollectCurvature(double h, const std::vector<IslandBody*>& bodies,
                        const std::vector<ConstraintSource*>& sources);
  // Newton steps on the model of the rows linearized at v (docs/math.md §5.8, model steps), from
  // v + alpha d while the model line search stops below settings.model_step_alpha. The end point
  // is left in v_trial_ (v_ is restored); returns the decrease of the model's Phi.
  double StepOnModel(double alpha, const std::vector<IslandBody*>& bodies,
                     const PrimalSettings& settings, StepStats& stats);
  // Phi of the model at v_: 1/2 ||v - v*||_A^2 + 1/2 (v - v_lin)^T G (v - v_lin) + the rows'
  // terms with g_c linear in v (v_lin = model_base_); sets model_gw_ = G (v - v_lin).
  double CalcModelMerit(const std::vector<IslandBody*>& bodies);
  // StepOnModel from the line search's alpha, then the Armijo test at its end point against
  // phi0 (rows evaluated there); false (the base point restored) when it fails.
  bool TryModelSteps(double h, double alpha, double phi0, const std::vector<IslandBody*>& bodies,
                     const std::vector<ConstraintSource*>& sources, const SqpSettings& settings,
                     StepStats& stats);
  // Stage: one Newton step on Phi from v_ (rows collected at v_); returns false when v_ is
  // stationary (Newton decrement below tolerance) and nothing moved.
  bool TakeNewtonStep(double h, const std::vector<IslandBody*>& bodies,
                      const std::vector<ConstraintSource*>& sources, const SqpSettings& settings,
                      StepStats& stats);
  // Whether the Newton step d still moves a row violated by more than the tolerance by more than
  // PrimalSettings::newton_row_move_fraction of it (the decrement test's exception).
  bool MovesViolatedRows(double h, const SqpSettings& settings) const;
  // Whether (v, Proj(y(v))) at the rows collected at v passes the certificate (the inner loop's
  // early stop, PrimalSettings::stop_newton_on_certificate); leaves lambda_ = Proj(y(v)).
  bool IsNewtonIterateCertified(const std::vector<IslandBody*>& bodies, double h,
                                const SqpSettings& settings);
  // Stage, at a certified iterate: the warm start of the next step (iterate_) from the
  // multipliers that certified this one, slack limit rows from lambda_bar.
  void StoreCertifiedWarmStart(double violation_tolerance);
  // lambda_c = Proj_c(y_c(v)) and D_c at v (row velocities jv_ = J v).
  void CalcProjectedMultipliers();
  // grad = A(v - v*) - J^T lambda on free blocks.
  void CalcGradient(const std::vector<IslandBody*>& bodies);
  // Stage: which bodies keep their last factor as the preconditioner (stale_), by its cost.
  void ChooseFactorReuse(const std::vector<IslandBody*>& bodies, const PrimalSettings& settings);
  // N_b = A_b + G_b + sum rho D J^T J (same-body blocks of rows held on the pattern), factored
  // for the bodies that do not keep their factor. Returns the number of factorizations.
  // When that factorization fails with G, G's indefinite element blocks are clamped first if
  // clamp_on_failure (PrimalSettings::clamp_curvature_on_failure), else G is dropped; then again.
  int AssembleNewtonMatrices(const std::vector<IslandBody*>& bodies, bool clamp_on_failure);
  // d = -H^-1 grad: one solve per body when H = N, else PCG with N as preconditioner. Returns the
  // PCG iterations (1 for the direct solve).
  int SolveNewtonStep(const std::vector<IslandBody*>& bodies, const PrimalSettings& settings);
  // out = H u (exact operator, matrix-free rows).
  void ApplyHessian(const std::vector<IslandBody*>& bodies, const std::vector<VecX>& u,
                    std::vector<VecX>& out);
  // Step length minimizing the linearized model of Phi along d (root of its convex slope), with
  // a0 = d^T grad of the model's quadratic part at v.
  double SearchModelLine(const std::vector<IslandBody*>& bodies, double a0);
  // Slope psi'(alpha) and curvature psi''(alpha) of the linearized model along d.
  void CalcSlope(double alpha, double a0, double a1, double& slope, double& curvature) const;
  // Phi at the collected rows and velocities v (lambda_bar, rho as collected).
  double CalcMerit(const std::vector<IslandBody*>& bodies, const std::vector<VecX>& v);
  // Its row part sum_c P_c(y_c) / rho_c.
  double CalcRowMerit(const std::vector<VecX>& v) const;
  // Adds scale * J_p^T J_q (same-body blocks) to the bodies' Newton matrices.
  void AddRowProduct(const std::vector<IslandBody*>& bodies, int p, int q, double scale);
  // out += rho D J^T (J u) over the rows (H's row part, matrix-free).
  void AddRowHessianTimes(const std::vector<VecX>& u, std::vector<VecX>& out) const;

  IslandRows rows_;
  KeyedMultipliers iterate_;   // lambda_bar of this step by key (certified: the next warm start)
  VecX lambda_bar_, lambda_;   // estimates, and Proj(y(v)) at the Newton iterate
  VecX reported_;              // the multipliers of the last certificate (multipliers())
  VecX work_lambda_;           // the warm start being stored (StoreCertifiedWarmStart)
  VecX newton_reported_;       // ... of the Newton loop's certificate
  VecX rho_, g0_, jv_, s_;     // penalties, g_c(v) = g0 + J v, J v, J d
  KeyedMultipliers kept_rho_;  // limit rows' rho of this multiplier iteration by key
  VecX fresh_rho_;             // rho at the rows' current J, before the kept values (CalcPenalties)
  bool rho_kept_ = false;
  KeyedMultipliers last_violation_;  // limit rows' stall residual at the last multiplier iteration
  KeyedMultipliers kept_growth_;     // limit rows' rho growth (> 1) of this step by key
  VecX last_, growth_;               // the two by row (scratch)
  VecX d_unit_;                      // D_c of scalar rows (0 or 1)
  std::vector<Eigen::Matrix2d> d_disk_;  // D of a friction pair, on its first tangent row
  std::vector<char> in_pattern_;         // row's same-body blocks fit the patterns
  bool coupled_ = false;                 // some row is two-sided or off-pattern: PCG
  std::vector<char> stale_;              // body keeps its last factor (ChooseFactorReuse)
  bool any_stale_ = false;
  double stale_budget_ = 0.0;      // CG iterations a kept factor may take before a refactor
  bool refactor_next_ = false;     // the last kept factor took too many: refactor
  double violation_ = 0.0;         // largest row violation at the collected rows
  double last_alpha_ = 0.0;        // step length of the last accepted plain Newton step
  double last_decrement_ = 0.0;    // its Newton decrement over ||v - v*||_A^2
  bool newton_certified_ = false;  // the Newton loop stopped on the certificate ...
  KktResiduals newton_kkt_;        // ... with these residuals at (v, Proj(y(v)))
  // Model steps: the linearization point v_lin, G (v - v_lin), and the plain step kept aside.
  std::vector<VecX> model_base_, model_gw_, model_d0_;
  bool model_steps_off_ = false;  // a model step fell short of its model in this step (solve)
  double line_a0_ = 0.0, line_dAd_ = 0.0;  // d^T A (v - v*) and d^T A d of the model line search
  CurvatureMetric curvature_;
  // Consecutive rows on the same nodes of one body (one element's rows): their summed
  // rho D J^T J as one dense block, scattered into the Newton matrix once.
  struct RowGroup {
    int body = -1, num_nodes = 0;
    int element = -1;  // the rows' element (element-local rows), else -1
    std::array<int, 2 * kMaxRowNodes> nodes{};
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6 * kMaxRowNodes, 6 * kMaxRowNodes>
        block;
    void Clear();
    bool Matches(const ConstraintRow& row) const;
    void Start(const ConstraintRow& row);
    void Add(const ConstraintRow& row, double scale);
    void Scatter(const std::vector<IslandBody*>& bodies);
  };
  RowGroup group_;
  std::vector<VecX> v_, v_trial_, d_, grad_, work_, r_, z_, p_, hp_;
  std::vector<VecX> w_, aw_;  // v - v* and A (v - v*) at the Newton iterate (CalcGradient)
  std::vector<VecX> warm_v_;  // the warm-start candidate (ChooseStartVelocities)
  // The rows and velocities of the line search's base point (restored when no trial is taken).
  struct BasePoint {
    IslandRows rows;
    VecX lambda_bar, rho, g0;
    std::vector<char> in_pattern;
    bool coupled = false;
    double violation = 0.0;
    std::vector<VecX> v;
    void Save(const PrimalSolver& s) {
      rows = s.rows_;
      lambda_bar = s.lambda_bar_;
      rho = s.rho_;
      g0 = s.g0_;
      in_pattern = s.in_pattern_;
      coupled = s.coupled_;
      violation = s.violation_;
      v = s.v_;
    }
    void Restore(PrimalSolver& s) const {
      s.rows_ = rows;
      s.lambda_bar_ = lambda_bar;
      s.rho_ = rho;
      s.g0_ = g0;
      s.in_pattern_ = in_pattern;
      s.coupled_ = coupled;
      s.violation_ = violation;
      s.v_ = v;
      s.jv_.resize(s.rows_.size());
      s.s_.setZero(s.rows_.size());
    }
  };
  BasePoint base_;
  std::vector<VecX> a_dv_;    // A (v - v*) per body at the last certificate's v ...
  std::vector<VecX> a_dv_v_;  // ... that v (empty: none this step)
};

}  // namespace taut
