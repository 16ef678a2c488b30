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

IslandSolverKind IslandSolver::ChooseAuto(int rows, int free_dofs, int primal_steps_left) {
  const bool many_rows = rows > kPrimalRowsPerDof * free_dofs;
  return many_rows || primal_steps_left > 0 ? IslandSolverKind::kPrimal : IslandSolverKind::kDual;
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
  return ChooseAuto(last_rows_, free_dofs, primal_steps_left_);
}

void IslandSolver::Solve(double h, const std::vector<IslandBody*>& bodies,
                         const std::vector<ConstraintSource*>& sources, const SqpSettings& settings,
                         StepStats& stats) {
  const IslandSolverKind kind = ChoosePath(bodies, settings);
  if (primal_steps_left_ > 0) --primal_steps_left_;
  if (kind == IslandSolverKind::kPrimal) {
    primal_.Solve(h, bodies, sources, settings, warm_, stats);
    solved_primal_ = true;
  } else {
    const bool retry =
        settings.solver == IslandSolverKind::kAuto && settings.retry_failed_dual_on_primal;
    KeyedMultipliers warm_start;
    if (retry) {
      warm_start = warm_;
      start_v_.resize(bodies.size());
      for (size_t b = 0; b < bodies.size(); ++b) start_v_[b] = bodies[b]->v();
    }
    SolveDual(h, bodies, sources, settings, stats);
    if (retry && !stats.converged) RetryOnPrimal(h, bodies, sources, settings, warm_start, stats);
  }
  last_rows_ = stats.rows_total();
}

void IslandSolver::SolveDual(double h, const std::vector<IslandBody*>& bodies,
                             const std::vector<ConstraintSource*>& sources,
                             const SqpSettings& settings, StepStats& stats) {
  std::swap(dual_.mutable_warm_starts(), warm_);
  dual_.Solve(h, bodies, sources, settings, stats);
  std::swap(dual_.mutable_warm_starts(), warm_);
  solved_primal_ = false;
  // Measured failure of a limit-only island: the next steps go to the primal path (kAuto
  // only). Islands with contact or joint rows stay dual: there the primal path failed more
  // steps than the dual (finger: 46 vs 23 of 493, docs/report.md).
  bool limit_rows_only = true;
  for (const RowTypeInfo& info : kRowTypes)
    if (!info.is_limit && stats.rows_of(info.type) > 0) limit_rows_only = false;
  if (!stats.converged && limit_rows_only && settings.solver == IslandSolverKind::kAuto) {
    primal_steps_left_ = primal_window_;
    primal_window_ = std::min(2 * primal_window_, kMaxPrimalSteps);
  }
}

void IslandSolver::RetryOnPrimal(double h, const std::vector<IslandBody*>& bodies,
                                 const std::vector<ConstraintSource*>& sources,
                                 const SqpSettings& settings, const KeyedMultipliers& warm_start,
                                 StepStats& stats) {
  dual_v_.resize(bodies.size());
  for (size_t b = 0; b < bodies.size(); ++b) {
    dual_v_[b] = bodies[b]->v();
    bodies[b]->set_v(start_v_[b]);
  }
  KeyedMultipliers warm = warm_start;
  StepStats retry;
  primal_.Solve(h, bodies, sources, settings, warm, retry);
  if (retry.converged || CalcCertificateError(retry) < CalcCertificateError(stats)) {
    AddDroppedSolveWork(stats, retry);
    stats = retry;
    warm_ = std::move(warm);
    solved_primal_ = true;
  } else {
    AddDroppedSolveWork(retry, stats);
    for (size_t b = 0; b < bodies.size(); ++b) bodies[b]->set_v(dual_v_[b]);
  }
  stats.islands_retried++;
}

}  // namespace taut
