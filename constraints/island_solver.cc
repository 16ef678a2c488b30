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

void IslandSolver::Solve(double h, const std::vector<IslandBody*>& bodies,
                         const std::vector<ConstraintSource*>& sources, const SqpSettings& settings,
                         StepStats& stats) {
  IslandSolverKind kind = settings.solver;
  if (kind == IslandSolverKind::kAuto) {
    int free_dofs = 0;
    for (const IslandBody* body : bodies)
      for (int i = 0; i < body->num_blocks(); ++i) free_dofs += body->is_free_block(i) ? 3 : 0;
    kind = ChooseAuto(last_rows_, free_dofs, primal_steps_left_);
  }
  if (primal_steps_left_ > 0) --primal_steps_left_;
  if (kind == IslandSolverKind::kPrimal) {
    primal_.Solve(h, bodies, sources, settings, warm_, stats);
    solved_primal_ = true;
  } else {
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
  last_rows_ = stats.rows_total();
}

}  // namespace taut
