// The constrained step of one island (docs/architecture.md §3, stage 6): the papers' dual path (PGS
// per QP inside the SQP, constraints/sqp_solver.h) or the primal path (augmented-Lagrangian Newton,
// constraints/primal_solver.h), chosen per island and step. Both share rows, keys and warm starts.
#pragma once

#include <algorithm>
#include <vector>

#include "constraints/primal_solver.h"
#include "constraints/sqp_solver.h"

namespace taut {

// A run of steps that follows a measured event (a path failing, a retry failing): Open() starts
// `next` steps and doubles `next` for the following event, up to a cap; Consume() tells whether a
// step falls in the run and counts it.
struct StepWindow {
  int left = 0;  // steps of the current run still to come
  int next;      // length of the next run
  void Open(int max_steps) {
    left = next;
    next = std::min(2 * next, max_steps);
  }
  bool Consume() {
    if (left == 0) return false;
    --left;
    return true;
  }
};

class IslandSolver {
 public:
  // Rows per free DOF from which kAuto takes the primal path (docs/solver.md "Two paths"): the
  // dual's cost grows like m n + m^2 per SQP iteration and W is rank-deficient once m approaches
  // n; the primal's cost is one sparse factorization per Newton iteration.
  static constexpr double kPrimalRowsPerDof = 0.3;

  // Solves the island's step into `stats` (fresh for each island: a retried island's are replaced
  // by the kept solve's); the path kept is counted in stats.islands_dual / islands_primal.
  void Solve(double h, const std::vector<IslandBody*>& bodies,
             const std::vector<ConstraintSource*>& sources, const SqpSettings& settings,
             StepStats& stats);
  // Steps the primal path keeps a limit-only island after the dual path failed its certificate
  // there; each further failure after returning doubles it, up to kMaxPrimalSteps.
  static constexpr int kPrimalStepsAfterDualFailure = 20;
  // A certified dual step of a limit-only island that took more SQP iterations than this opens
  // the same window: measured, the primal path solves such islands in about one multiplier
  // iteration (hex beam at 0.1 J: dual 9.5 SQP iterations per step, primal 1.0).
  static constexpr int kCostlyDualSqpIterations = 4;
  static constexpr int kMaxPrimalSteps = 640;
  // Steps the dual path keeps an island after the primal path failed its certificate there and
  // the dual retry certified the step; each further such failure doubles it, up to kMaxDualSteps;
  // a dual failure the primal retry certifies ends it. The gripper had 16 primal failures of
  // 50-110 ms, each certified by a dual retry of 1-18 ms; its steps.csv ratio went 22.7x -> 16.9x
  // with a window of 20 and 11.1x with 80 (the dual path alone 10.8x, same run).
  static constexpr int kDualStepsAfterPrimalFailure = 80;
  // A certified primal step of an island coupled to rigid bodies or multibodies (joint or
  // rigid-contact rows) that took more Newton iterations than this opens the same window: measured
  // on the gripper (auto), once its primal steps certified, they took 9 Newton iterations (5.7 ms)
  // where the dual path takes 4.9 ms.
  static constexpr int kCostlyPrimalNewtonIterations = 8;
  static constexpr int kMaxDualSteps = 640;
  // Steps without retries on an island after a retry there failed too (both paths failed the
  // step); each further failed retry doubles it, up to kMaxStepsWithoutRetry. vertical_beam's
  // collapsed columns: every dual retry of a failed primal step failed, at 340-1010 ms each.
  static constexpr int kStepsWithoutRetryAfterFailedRetry = 20;
  static constexpr int kMaxStepsWithoutRetry = 640;

  // The path kAuto takes for an island with `rows` rows (last step) on `free_dofs` free DOFs:
  // the primal path while `primal_steps_left` > 0 (after a failed dual step), else the dual path
  // while `dual_steps_left` > 0 (after a failed primal step the dual retry certified), else by
  // rows per free DOF.
  static IslandSolverKind ChooseAuto(int rows, int free_dofs, int primal_steps_left = 0,
                                     int dual_steps_left = 0);

  // What the next Solve depends on from earlier ones: the warm starts by row key and the path
  // rule's memory. Saved and restored by world snapshots (bullet_bridge/world_snapshot.h).
  struct State {
    KeyedMultipliers warm;                               // last step's multipliers by row key
    int last_rows = 0;                                   // rows at the end of the last step
    StepWindow primal{0, kPrimalStepsAfterDualFailure};  // primal path after a dual failure
    StepWindow dual{0, kDualStepsAfterPrimalFailure};    // dual path after a primal failure
    StepWindow no_retry{0, kStepsWithoutRetryAfterFailedRetry};  // no retries after a failed one
    bool primal_refactor_next = false;  // PrimalSolver::refactor_next of the last primal solve
  };
  State SaveState() const {
    State state;
    SaveState(state);
    return state;
  }
  // The same into `state`, reusing its storage.
  void SaveState(State& state) const {
    state = state_;
    state.primal_refactor_next = primal_.refactor_next();
  }
  void RestoreState(const State& state) {
    state_ = state;
    primal_.set_refactor_next(state.primal_refactor_next);
  }

  // The rows of the last Solve at its final velocities and their multipliers, one per row
  // (contact rows: impulses [N s]; limit rows [N m s]), from the path that ran. Reading them
  // changes nothing; valid until the next Solve.
  const IslandRows& last_rows() const { return solved_primal_ ? primal_.rows() : dual_.rows(); }
  const VecX& last_multipliers() const {
    return solved_primal_ ? primal_.multipliers() : dual_.multipliers();
  }

 private:
  // The path of this step: settings.solver, or for kAuto the rule of ChooseAuto.
  IslandSolverKind ChoosePath(const std::vector<IslandBody*>& bodies,
                              const SqpSettings& settings) const;
  // One solve on the path `kind` (the dual with the failure rule of kAuto).
  void SolveOn(IslandSolverKind kind, double h, const std::vector<IslandBody*>& bodies,
               const std::vector<ConstraintSource*>& sources, const SqpSettings& settings,
               StepStats& stats);
  // The dual path, with the failure rule of kAuto (the primal window: after a failed or costly
  // step of a limit-only island, or a stall of an island with limit rows).
  void SolveDual(double h, const std::vector<IslandBody*>& bodies,
                 const std::vector<ConstraintSource*>& sources, const SqpSettings& settings,
                 StepStats& stats);
  // After a failed step (kAuto, retry_failed_step_on_other_path): the path `other` from the
  // step's start velocities (start_v_) and warm starts (a dual retry: `warm_start`, the step's
  // own; a primal retry: the failed dual answer's multipliers), at most retry_max_iterations
  // iterations; keeps the better answer (a dual retry that stalled as locally infeasible only
  // when certified). Returns whether the retry certified the step.
  bool RetryOn(IslandSolverKind other, double h, const std::vector<IslandBody*>& bodies,
               const std::vector<ConstraintSource*>& sources, const SqpSettings& settings,
               KeyedMultipliers warm_start, StepStats& stats);

  SqpSolver dual_;
  PrimalSolver primal_;
  State state_;                          // warm starts, last row count, the path rule's windows
  bool solved_primal_ = false;           // the last Solve took the primal path
  std::vector<VecX> start_v_, first_v_;  // retry: velocities at the start and of the first path
};

}  // namespace taut
