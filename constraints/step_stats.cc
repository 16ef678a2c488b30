#include "constraints/step_stats.h"

#include <algorithm>

#include "plugin/common.h"

namespace taut {

int& StepStats::rows_of(RowType type) {
  switch (type) {
    case RowType::kStrainLimit:
      return rows_strain;
    case RowType::kEnergyLimit:
      return rows_energy;
    case RowType::kContact:
      return rows_contact;
    case RowType::kRigidContact:
      return rows_rigid_contact;
    case RowType::kJoint:
      return rows_joint;
    case RowType::kNodeHeight:
      return rows_node_height;
  }
  TAUT_ASSERT(false);
  return rows_joint;
}

int StepStats::rows_total() const {
  int total = 0;
  for (const RowTypeInfo& info : kRowTypes) total += rows_of(info.type);
  return total;
}

namespace {

// total += part for the solver's iteration work (time, sweeps, iterations, factorizations): what a
// solve costs, whether its answer is kept or dropped.
void AddSolveIterations(const StepStats& part, StepStats& total) {
  total.ms_rows += part.ms_rows;
  total.ms_solve += part.ms_solve;
  total.pgs_sweeps += part.pgs_sweeps;
  total.restoration_iterations += part.restoration_iterations;
  total.active_set_solves += part.active_set_solves;
  total.rows_discovered += part.rows_discovered;
  total.newton_iterations += part.newton_iterations;
  total.pcg_iterations += part.pcg_iterations;
  total.newton_factorizations += part.newton_factorizations;
}

// total += part for the constraint work that adds up over islands and over substeps.
void AddWork(const StepStats& part, StepStats& total) {
  AddSolveIterations(part, total);
  for (const RowTypeInfo& info : kRowTypes) total.rows_of(info.type) += part.rows_of(info.type);
  total.islands_dual += part.islands_dual;
  total.islands_primal += part.islands_primal;
  total.islands_retried += part.islands_retried;
}

// worst = max(worst, part) for every violation and residual [C units or relative, as in
// StepStats]; converged only when both are.
void KeepWorst(const StepStats& part, StepStats& worst) {
  worst.stationarity = std::max(worst.stationarity, part.stationarity);
  worst.lcp_residual = std::max(worst.lcp_residual, part.lcp_residual);
  worst.violation_before = std::max(worst.violation_before, part.violation_before);
  worst.violation_after = std::max(worst.violation_after, part.violation_after);
  worst.converged = worst.converged && part.converged;
  worst.kkt_primal = std::max(worst.kkt_primal, part.kkt_primal);
  worst.kkt_complementarity = std::max(worst.kkt_complementarity, part.kkt_complementarity);
  worst.kkt_dual = std::max(worst.kkt_dual, part.kkt_dual);
  for (int i = 0; i < kNumRowTypes; ++i) {
    worst.kkt_primal_by_type[i] = std::max(worst.kkt_primal_by_type[i], part.kkt_primal_by_type[i]);
    worst.kkt_complementarity_by_type[i] =
        std::max(worst.kkt_complementarity_by_type[i], part.kkt_complementarity_by_type[i]);
  }
}

// total += substep for the world's own timers [ms] and counts of one substep.
void AddWorldTimesAndCounts(const StepStats& substep, StepStats& total) {
  total.ms_unconstrained += substep.ms_unconstrained;
  total.ms_integrate += substep.ms_integrate;
  total.ms_rigid += substep.ms_rigid;
  total.ms_total += substep.ms_total;
  total.ms_stage_begin_steps += substep.ms_stage_begin_steps;
  total.ms_stage_partners += substep.ms_stage_partners;
  total.ms_stage_islands += substep.ms_stage_islands;
  total.ms_stage_couple_rigid += substep.ms_stage_couple_rigid;
  total.ms_stage_row_sources += substep.ms_stage_row_sources;
  total.ms_stage_bullet_solver += substep.ms_stage_bullet_solver;
  total.ms_stage_solve_islands += substep.ms_stage_solve_islands;
  total.ms_stage_end_steps += substep.ms_stage_end_steps;
  total.islands += substep.islands;
  total.rigid_bodies_coupled += substep.rigid_bodies_coupled;
  total.substeps += substep.substeps;
}

}  // namespace

void AddIslandStats(const StepStats& island, StepStats& step) {
  AddWork(island, step);
  step.sqp_iterations = std::max(step.sqp_iterations, island.sqp_iterations);
  KeepWorst(island, step);
}

void AddDroppedSolveWork(const StepStats& dropped, StepStats& kept) {
  AddSolveIterations(dropped, kept);
  kept.sqp_iterations += dropped.sqp_iterations;
}

void AddSubstepStats(const StepStats& substep, StepStats& call) {
  AddWork(substep, call);
  call.sqp_iterations += substep.sqp_iterations;
  KeepWorst(substep, call);
  AddWorldTimesAndCounts(substep, call);
}

}  // namespace taut
