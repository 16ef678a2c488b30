// Settings of the island solvers: the SQP loop with its dual (PGS) and primal (Newton) paths.
#pragma once

#include "constraints/active_set_polish.h"
#include "constraints/pgs_solver.h"

namespace taut {

// Which path solves an island's constrained step (constraints/island_solver.h).
enum class IslandSolverKind {
  kAuto,    // per island and step, by rows per free DOF (IslandSolver::kPrimalRowsPerDof)
  kDual,    // the papers' path: one PGS per QP on W = J A^-1 J^T inside the SQP
  kPrimal,  // augmented-Lagrangian Newton on the velocities (constraints/primal_solver.h)
};

// Name of a solver kind for output ("auto", "dual", "primal").
const char* GetIslandSolverName(IslandSolverKind kind);

// The primal path (constraints/primal_solver.h).
struct PrimalSettings {
  int max_iterations = 40;         // SQP (multiplier) iterations per step (cap)
  int max_newton_iterations = 12;  // Newton iterations per linearized problem (cap)
  double penalty_scale = 1e3;      // rho_c w_c: penalty over the row's diagonal compliance
  // A limit row still violated whose violation fell by less than half over a multiplier
  // iteration gets penalty_growth times its rho, up to max_penalty_growth times (1 = off).
  double penalty_growth = 3.0;
  double max_penalty_growth = 10.0;
  // From multiplier iteration late_growth_iteration on, the cap is late_max_penalty_growth: a step
  // that has not converged by then has rows whose Newton model holds only near the iterate (frame
  // derivatives near repeated stretches, docs/math.md §5.8, late growth); steps converging
  // earlier are unchanged.
  int late_growth_iteration = 10;
  double late_max_penalty_growth = 1000.0;
  // ... and, once the iterate is feasible, a row with full curvature that pushes while slack by
  // more than the tolerance, by its complementarity residual C (docs/math.md §5.8).
  bool grow_on_slack_push = true;
  double newton_tolerance = 1e-9;  // stop when the Newton decrement < this * ||v - v*||_A^2
  // ... unless the step moves a row violated by more than the tolerance (its C by h J_c d) by more
  // than newton_row_move_fraction of it: with a tight tolerance a limit row's share of Phi falls
  // below the relative decrement test (docs/math.md §5.8, rows still moving; 0 = off).
  double newton_row_move_fraction = 0.1;
  // ... or as soon as (v, Proj(y(v))) passes the step's certificate after a Newton step, with
  // distance rows (contacts, joints) held to newton_stop_distance_factor of their tolerance.
  bool stop_newton_on_certificate = true;
  double newton_stop_distance_factor = 0.1;
  // ... or once a plain Newton step near Phi's minimizer (alpha >= 1/2, relative decrement below
  // newton_stall_decrement) closes less than newton_stall_fraction of the gap between the rows'
  // violation and its tolerance: Phi's minimizer is violated, and the multiplier update, not more
  // Newton steps, moves the rows on (newton_stall_fraction 0 = off; docs/math.md §5.8). Only in
  // the first newton_stall_iterations multiplier iterations: later ones solve Phi fully.
  double newton_stall_fraction = 0.05;
  double newton_stall_decrement = 1e-2;
  int newton_stall_iterations = 4;
  int max_pcg_iterations = 200;  // coupled islands: PCG on the Newton step
  double pcg_tolerance = 1e-10;  // relative residual of that PCG
  bool curvature = true;         // lagged row curvature G in the model and H
  // When H with G does not factor, G's element blocks are clamped exactly to their positive
  // semi-definite part and H factored again before G is dropped for the iteration (§5.9).
  bool clamp_curvature_on_failure = true;
  // Model steps: when the model line search stops short of the Newton step (alpha below
  // model_step_alpha: a row turns active along d), up to max_model_steps further Newton steps on
  // the same linearization (rows, rho and G fixed), by PCG preconditioned with this iteration's
  // factor (at most model_pcg_iterations), before the rows are evaluated again; the end point
  // must pass the same Armijo test, else the plain step is taken (docs/math.md §5.8, model steps).
  int max_model_steps = 2;
  double model_step_alpha = 0.5;
  int model_pcg_iterations = 10;
  // The warm-start candidate v* + A^-1 J^T lambda_bar of the step's start is collected (its rows,
  // an SVD per element near its limits) only when Phi of the rows of v*, linearized there, ranks
  // it below the other candidates (false: always; docs/math.md §5.8, the start).
  bool screen_warm_start = true;
  // Factor reuse: a body whose H costs more than min_refactor_cost preconditioned CG iterations
  // to factor keeps its last factor (from an earlier Newton iteration or step) as the
  // preconditioner of CG on the exact H, to stale_pcg_tolerance, while CG needs fewer than half
  // that cost; then it refactors.
  bool reuse_factorization = true;
  double min_refactor_cost = 8.0;
  double stale_pcg_tolerance = 1e-6;
};

// PGS settings of the QPs: 100 sweeps at most.
inline PgsSettings DefaultPgs() {
  PgsSettings pgs;
  pgs.max_sweeps = 100;
  pgs.tolerance = 1e-4;  // in w units (1/s): C error h * 1e-4, far below the SQP tolerance
  return pgs;
}

// Solver settings (defaults suit interactive use; the report sweeps them).
struct SqpSettings {
  int max_iterations = 10;            // SQP iterations per step (cap), before restoration
  double violation_tolerance = 1e-3;  // stop when max(0, -C) <= this (C is a fraction of the limit)
  double contact_tolerance = 1e-5;    // [m] the same for contact and joint rows, whose C is a
                                      // distance (rigid contacts: h times a velocity error)
  double stationarity_tolerance = 1e-2;  // ... and the relative stationarity (kkt_certificate.h)
  // Factor from a distance row's C [m] to limit-row units, so one tolerance applies to every row.
  double CalcDistanceScale() const { return violation_tolerance / contact_tolerance; }
  int max_restoration_iterations = 10;  // push-only iterations after the cap while infeasible
  int max_line_search_halvings = 8;     // merit backtracking: alpha = 1, 1/2, ...
  // Dual path (docs/math.md §5.7, certificate steps): a full QP step that the merit rejects is
  // still taken when it lowers the certificate's residual (CalcCertificateResidual at its own
  // rows) by 10 % and leaves no row violated by more than full_step_violation_factor x the
  // tolerance (or than now); and the SQP stops once the step is certified, not when it is only
  // feasible and stationary. Off: the merit alone decides, and feasible and stationary stops.
  bool certificate_steps = true;
  double full_step_violation_factor = 10.0;
  // Dual path: rows the full QP step violates that the QP did not have (elements and contacts
  // outside the activation margin at x_k, which v* pushes past their limit) join the QP, shifted
  // to x_k by their Jacobian, and the QP is solved again, up to this many times per SQP
  // iteration (docs/math.md §5.7, "rows found at the QP step"). 0: off.
  int max_row_discovery_passes = 3;
  double stalled_step = 0.1;       // feasible and last alpha below this: stop (stalled)
  PgsSettings pgs = DefaultPgs();  // sweeps and tolerance of each QP
  bool polish_active_set = true;   // refine an unconverged PGS answer by active-set solves
  ActiveSetPolishSettings polish;
  bool warm_start = true;  // warm-start lambda from the previous step by row key
  // Dual path: each QP in the metric N = A + G, G the limit rows' curvature at (x_k, lambda_k)
  // (constraints/curved_dual_metric.h): one more factorization per SQP iteration, for a
  // faster-than-linear SQP; the answer it converges to is the same. Off: the papers' metric A.
  bool dual_curvature = false;
  // Dual path: the SQP starts from v* + A^-1 J_0^T lambda_0, the warm multipliers on the rows at
  // the step's start positions, instead of v* (docs/math.md §5.7, warm-start velocity).
  // From there the SQP runs at least one QP and is certified only with distance rows (contacts,
  // joints) within warm_stop_distance_factor of their tolerance; not certified (or without rows
  // there), it starts over from v*.
  bool warm_start_velocity = true;
  double warm_stop_distance_factor = 0.1;
  // Which island solver runs (constraints/island_solver.h) and the primal path's settings.
  IslandSolverKind solver = IslandSolverKind::kAuto;
  PrimalSettings primal;
  // kAuto only: when the path taken fails the step's certificate, solve the step again from its
  // start on the other path and keep whichever answer has the smaller residual (converged
  // first). Costs a second solve on failed steps only. Default true.
  bool retry_failed_step_on_other_path = true;
  // The retried path's iteration cap (primal: multiplier iterations, dual: SQP iterations), when
  // below its own. Retries that certify a step took 1 or 2 (box_on_sphere, hex_beam, gripper);
  // an advance the finger's press had locked ran the primal path's 40 for nothing (65 ms).
  int retry_max_iterations = 10;
};

// Throws InputError naming the field ("SqpSettings::primal.penalty_scale = 0 must be finite and
// > 0") unless every field of `settings` is in its documented range. DeformableWorld checks its
// solver settings with it before each stepSimulation, so a bad setting changes no state.
void ValidateSqpSettings(const SqpSettings& settings);

}  // namespace taut
