#include "constraints/island_solver.h"

#include <algorithm>
#include <utility>

namespace taut {

const char* GetIslandSolverName(IslandSolverKind kind) {
  switch (kind) {
    case IslandSolverKind::kAuto:
      return "auto";
    case IslandSolverKind::kDual:
      return "dual";
    case IslandSolverKind::kPrimal:
      return "primal";
  }
  return "unknown";
}

IslandSolverKind IslandSolver::ChooseAuto(int rows, int free_dofs, int primal_steps_left,
                                          int dual_steps_left) {
  if (primal_steps_left > 0) return IslandSolverKind::kPrimal;
  if (dual_steps_left > 0) return IslandSolverKind::kDual;
  return rows > kPrimalRowsPerDof * free_dofs ? IslandSolverKind::kPrimal : IslandSolverKind::kDual;
}

namespace {

// The residual a retried island compares: the larger of primal feasibility and complementarity
// of the certificate (C units, constraints/kkt_certificate.h).
double CalcCertificateError(const StepStats& stats) {
  return std::max(stats.kkt_primal, stats.kkt_complementarity);
}

}  // namespace

IslandSolverKind IslandSolver::ChoosePath(const std::vector<IslandBody*>& bodies,
                                          const SqpSettings& settings) const {
  if (settings.solver != IslandSolverKind::kAuto) return settings.solver;
  int free_dofs = 0;
  for (const IslandBody* body : bodies)
    for (int i = 0; i < body->num_blocks(); ++i) free_dofs += body->is_free_block(i) ? 3 : 0;
  return ChooseAuto(state_.last_rows, free_dofs, state_.primal.left, state_.dual.left);
}

void IslandSolver::Solve(double h, const std::vector<IslandBody*>& bodies,
                         const std::vector<ConstraintSource*>& sources, const SqpSettings& settings,
                         StepStats& stats) {
  const IslandSolverKind kind = ChoosePath(bodies, settings);
  state_.primal.Consume();
  state_.dual.Consume();
  const bool retries_suspended = state_.no_retry.Consume();
  const bool retry = settings.solver == IslandSolverKind::kAuto &&
                     settings.retry_failed_step_on_other_path && !retries_suspended;
  KeyedMultipliers warm_start;
  if (retry) {
    warm_start = state_.warm;
    start_v_.resize(bodies.size());
    for (size_t b = 0; b < bodies.size(); ++b) start_v_[b] = bodies[b]->v();
  }
  SolveOn(kind, h, bodies, sources, settings, stats);
  // A dual step that stopped because no push lowers the violation is locally infeasible (the
  // finger's locked advances): the primal retry failed there too, at three times the cost.
  const bool infeasible = kind == IslandSolverKind::kDual && dual_.stalled_infeasible();
  if (retry && !stats.converged && !infeasible) {
    const bool primal_failed = kind == IslandSolverKind::kPrimal;
    const IslandSolverKind other =
        primal_failed ? IslandSolverKind::kDual : IslandSolverKind::kPrimal;
    if (RetryOn(other, h, bodies, sources, settings, std::move(warm_start), stats)) {
      // Measured: the path that certified what the other could not keeps the island (the
      // primal for a limit-only island already does, SolveDual's rule).
      if (primal_failed) {
        state_.primal.left = 0;
        state_.dual.Open(kMaxDualSteps);
      } else {
        state_.dual.left = 0;
      }
    } else {
      // Both paths failed: retries here are suspended for a while (measured cost, no gain).
      state_.no_retry.Open(kMaxStepsWithoutRetry);
    }
  }
  state_.last_rows = stats.rows_total();
}

void IslandSolver::SolveOn(IslandSolverKind kind, double h, const std::vector<IslandBody*>& bodies,
                           const std::vector<ConstraintSource*>& sources,
                           const SqpSettings& settings, StepStats& stats) {
  if (kind == IslandSolverKind::kPrimal) {
    primal_.Solve(h, bodies, sources, settings, state_.warm, stats);
    solved_primal_ = true;
    // Measured cost of a certified primal step on an island coupled to rigid bodies or
    // multibodies (joint or rigid-contact rows: its Newton systems are solved by PCG): past
    // kCostlyPrimalNewtonIterations the next steps go to the dual path (kAuto only).
    const bool rigid_coupled =
        stats.rows_of(RowType::kJoint) > 0 || stats.rows_of(RowType::kRigidContact) > 0;
    if (settings.solver == IslandSolverKind::kAuto && stats.converged && rigid_coupled &&
        stats.newton_iterations > kCostlyPrimalNewtonIterations) {
      state_.primal.left = 0;
      state_.dual.Open(kMaxDualSteps);
    }
  } else {
    SolveDual(h, bodies, sources, settings, stats);
  }
}

void IslandSolver::SolveDual(double h, const std::vector<IslandBody*>& bodies,
                             const std::vector<ConstraintSource*>& sources,
                             const SqpSettings& settings, StepStats& stats) {
  std::swap(dual_.mutable_warm_starts(), state_.warm);
  dual_.Solve(h, bodies, sources, settings, stats);
  std::swap(dual_.mutable_warm_starts(), state_.warm);
  solved_primal_ = false;
  // Measured failure of a limit-only island: the next steps go to the primal path (kAuto
  // only). Islands with contact or joint rows stay dual: there the primal path failed more
  // steps than the dual (finger: 46 vs 23 of 493, docs/report.md).
  bool limit_rows_only = true, any_limit_row = false;
  for (const RowTypeInfo& info : kRowTypes) {
    if (stats.rows_of(info.type) == 0) continue;
    if (info.is_limit)
      any_limit_row = true;
    else
      limit_rows_only = false;
  }
  const bool costly = stats.sqp_iterations > kCostlyDualSqpIterations;
  // Except after a stall where no push lowers the violation, with limit rows: a row whose
  // linearization holds only in a tiny neighbourhood (a sliver's principal stretch, curvature
  // ~ 1/height^2) stalls every dual step from v* with the contacts left unresolved. The stress
  // suite's sliver cubes (V/l^3 = 1e-6, 1e-9, +-5 % limits) sank 6 cm into the ground in 20 such
  // steps, until a retry lifted them out at 11 m/s (energy growth 60x and 70x); the primal path
  // holds their contacts (penetration 1.3 mm, no energy growth). A finger's locked advance also
  // stalls, but the scene takes that step back, windows included.
  const bool stalled_on_limits = dual_.stalled_infeasible() && any_limit_row;
  if ((((!stats.converged || costly) && limit_rows_only) || stalled_on_limits) &&
      settings.solver == IslandSolverKind::kAuto) {
    state_.dual.left = 0;
    state_.primal.Open(kMaxPrimalSteps);
  }
}

bool IslandSolver::RetryOn(IslandSolverKind other, double h, const std::vector<IslandBody*>& bodies,
                           const std::vector<ConstraintSource*>& sources,
                           const SqpSettings& settings, KeyedMultipliers warm_start,
                           StepStats& stats) {
  // Keep the first answer (velocities, warm starts, path) to come back to.
  first_v_.resize(bodies.size());
  for (size_t b = 0; b < bodies.size(); ++b) {
    first_v_[b] = bodies[b]->v();
    bodies[b]->set_v(start_v_[b]);
  }
  KeyedMultipliers first_warm = std::move(state_.warm);
  const bool first_primal = solved_primal_;
  // A primal retry starts from the failed dual answer's multipliers: its first penalties and the
  // rows' curvature terms (docs/math.md §5.8) scale with them. From the previous step's, a first
  // step after the release starts at zero (stress cells, 1e-4 strain energy limits: U/U_max - 1
  // 0.627 -> 0.0055, and 0.388 -> 8e-4 for hexes). A dual retry keeps the previous step's: from
  // the failed primal answer's, the tet cantilever of energy limits at 10 % strain failed more.
  state_.warm = other == IslandSolverKind::kPrimal ? first_warm : std::move(warm_start);
  SqpSettings capped = settings;
  capped.max_iterations = std::min(settings.max_iterations, settings.retry_max_iterations);
  capped.primal.max_iterations =
      std::min(settings.primal.max_iterations, settings.retry_max_iterations);
  StepStats retry;
  SolveOn(other, h, bodies, sources, capped, retry);
  // A dual retry that stalled where no push lowers the violation leaves the contacts as v* had
  // them; by the certificate's error it still beat the primal answer of the sliver cubes
  // (SolveDual: 1.3 mm of penetration, growing 3 mm a step, against a sliver 2.8 %
  // past its limit), which sank again. Such a retry is kept only when certified.
  const bool stalled = other == IslandSolverKind::kDual && dual_.stalled_infeasible();
  if (retry.converged || (!stalled && CalcCertificateError(retry) < CalcCertificateError(stats))) {
    AddDroppedSolveWork(stats, retry);
    stats = retry;
  } else {
    AddDroppedSolveWork(retry, stats);
    state_.warm = std::move(first_warm);
    solved_primal_ = first_primal;
    for (size_t b = 0; b < bodies.size(); ++b) bodies[b]->set_v(first_v_[b]);
  }
  stats.islands_retried++;
  return retry.converged;
}

}  // namespace taut
