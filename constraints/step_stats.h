// Per-substep statistics of the deformable step, readable by the user and written by the demos,
// and how the figures of islands and of substeps add up.
#pragma once

#include "constraints/row_types.h"

namespace taut {

// What one world substep did and how long each stage took (docs/architecture.md §3, stage 8).
struct StepStats {
  // Time per stage [ms].
  double ms_unconstrained = 0.0;  // assemble forces and A, factor, solve v*
  double ms_rows = 0.0;           // evaluate constraint rows and Jacobians
  double ms_solve = 0.0;          // Delassus assembly, PGS, SQP updates
  double ms_integrate = 0.0;      // x = x0 + h v
  double ms_rigid = 0.0;          // Bullet's own rigid step
  double ms_total = 0.0;

  // Time per stage of DeformableWorld's substep [ms], docs/architecture.md §3 stage number first.
  // Measured one after the other inside ms_total; the rest of ms_total is Bullet's own (rigid
  // prediction, collision detection, integration of the rigid transforms).
  double ms_stage_begin_steps = 0.0;    // 2: unconstrained deformable step (= ms_unconstrained)
  double ms_stage_partners = 0.0;       // 3: swept bounds, rigid partners, deformable pairs
  double ms_stage_islands = 0.0;        // 4: union-find islands
  double ms_stage_couple_rigid = 0.0;   // 4: rigid bodies of deformable islands begin their step
  double ms_stage_row_sources = 0.0;    // 5: row sources, Bullet manifolds and joints per island
  double ms_stage_bullet_solver = 0.0;  // 6: Bullet's solver for the rigid-only islands
  double ms_stage_solve_islands = 0.0;  // 6: one SQP per deformable island (rows and solve)
  double ms_stage_end_steps = 0.0;      // 7: x = x0 + h v (= ms_integrate)

  // Constraint work.
  int rows_strain = 0;             // active strain-limit rows (last SQP iteration)
  int rows_energy = 0;             // active energy-limit rows
  int rows_contact = 0;            // deformable contact normal + friction rows
  int rows_rigid_contact = 0;      // Bullet rigid-rigid contact rows inside deformable islands
  int rows_joint = 0;              // Bullet joint and node attachment rows (bilateral)
  int rows_node_height = 0;        // node-height rows (a free node above z_min)
  int pgs_sweeps = 0;              // total over SQP iterations
  int active_set_solves = 0;       // QPs refined by a direct active-set solve
  int rows_discovered = 0;         // dual path: rows added at full QP steps (QPs solved again)
  int sqp_iterations = 0;          // including restoration iterations
  int restoration_iterations = 0;  // push-only iterations after the SQP cap
  // Violations in units of the limit rows' C (fraction of the limit): max(0, -C) of limit rows,
  // and of contact/joint rows (C in m) times violation_tolerance / contact_tolerance.
  double violation_before = 0.0;  // at the unconstrained prediction x*
  double violation_after = 0.0;   // at the end of the step
  double stationarity = 0.0;  // relative ||A(v - v*) - J^T lambda|| at the end (kkt_certificate.h)
  // Natural-map residual ||lambda - Proj_K(lambda - w)||_inf of the last QP at exit (PGS, after
  // any projected-Newton polish; docs/math.md §5.7) [units of lambda and w].
  double lcp_residual = 0.0;
  bool converged = true;  // every KKT residual below within tolerance at the end

  // Which island solver ran (constraints/island_solver.h): the papers' dual PGS path, the primal
  // augmented-Lagrangian Newton path, or none (no rows). With several islands: the count of each.
  int islands_dual = 0;
  int islands_primal = 0;
  int newton_iterations = 0;      // primal path: Newton iterations over all SQP iterations
  int pcg_iterations = 0;         // primal path: PCG iterations (1 per Newton step when local)
  int newton_factorizations = 0;  // primal path: Newton matrices factored (fewer than Newton
                                  // iterations when bodies keep their factor, PrimalSettings)
  // Islands whose step failed its certificate and was solved again on the other path
  // (SqpSettings::retry_failed_step_on_other_path); islands_dual / islands_primal count the path
  // whose answer was kept, the work counts and times include both solves.
  int islands_retried = 0;
  // Convergence certificate at the end of the step (constraints/kkt_certificate.h), worst island:
  double kkt_primal = 0.0;           // max(0, -C) of every row (distance rows scaled), C units
  double kkt_complementarity = 0.0;  // |C| of pushing rows, slip of sticking contacts, C units
  double kkt_dual = 0.0;             // distance of lambda from its set, relative to max |lambda|
  // The first two by row type (RowType order: strain, energy, contact, rigid contact, joint,
  // node height).
  double kkt_primal_by_type[kNumRowTypes] = {0, 0, 0, 0, 0, 0};
  double kkt_complementarity_by_type[kNumRowTypes] = {0, 0, 0, 0, 0, 0};

  int islands = 0;               // islands solved by the SQP (with at least one row source)
  int rigid_bodies_coupled = 0;  // dynamic rigid bodies solved inside deformable islands
  // World substeps these figures cover: 1 for one substep, their count in the totals of a whole
  // stepSimulation call (AddSubstepStats, DeformableWorld::last_call_stats).
  int substeps = 1;

  // The active-row counter of `type` (rows_strain, ... in kRowTypes order).
  int& rows_of(RowType type);
  int rows_of(RowType type) const { return const_cast<StepStats&>(*this).rows_of(type); }
  // Active rows of every type.
  int rows_total() const;
};

// Adds one island's SQP statistics to those of its substep `step`: row and solve times [ms] and
// the work counts summed, sqp_iterations the most of any island (the islands are independent
// solves), violations and residuals the worst island's, converged only when every island
// converged. The stage times, islands and rigid_bodies_coupled are the world's own.
void AddIslandStats(const StepStats& island, StepStats& step);

// Adds the work of a solve whose answer was dropped (a retried island, islands_retried) to the
// statistics of the one kept: row and solve times [ms], SQP, PGS, Newton and PCG counts summed
// (the solves ran one after the other); rows, paths, violations and residuals stay the kept's.
void AddDroppedSolveWork(const StepStats& dropped, StepStats& kept);

// Adds one substep's statistics to the totals of a whole stepSimulation call `call`: every time
// [ms] and every count (rows, iterations, islands, coupled rigid bodies, substeps) summed, so a
// per-substep mean is the total over `substeps`; violations and residuals the worst substep's;
// converged only when every substep converged. Start `call` from StepStats with substeps = 0.
void AddSubstepStats(const StepStats& substep, StepStats& call);

}  // namespace taut
