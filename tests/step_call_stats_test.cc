// How StepStats add up: islands into a substep (AddIslandStats), substeps into the totals of one
// stepSimulation call (AddSubstepStats, DeformableWorld::last_call_stats).
#include <btBulletDynamicsCommon.h>
#include <gtest/gtest.h>

#include <vector>

#include "bullet_bridge/deformable_world.h"
#include "plugin/box_tet_mesher.h"

namespace taut {
namespace {

// Stats whose every field is a different value derived from `seed`.
StepStats MakeStats(int seed, bool converged) {
  StepStats s;
  double* times[] = {&s.ms_unconstrained,
                     &s.ms_rows,
                     &s.ms_solve,
                     &s.ms_integrate,
                     &s.ms_rigid,
                     &s.ms_total,
                     &s.ms_stage_begin_steps,
                     &s.ms_stage_partners,
                     &s.ms_stage_islands,
                     &s.ms_stage_couple_rigid,
                     &s.ms_stage_row_sources,
                     &s.ms_stage_bullet_solver,
                     &s.ms_stage_solve_islands,
                     &s.ms_stage_end_steps};
  for (int k = 0; k < 14; ++k) *times[k] = 0.25 * (seed + 2 * k + 1);
  int* counts[] = {&s.rows_strain,
                   &s.rows_energy,
                   &s.rows_contact,
                   &s.rows_rigid_contact,
                   &s.rows_joint,
                   &s.pgs_sweeps,
                   &s.active_set_solves,
                   &s.sqp_iterations,
                   &s.restoration_iterations,
                   &s.islands_dual,
                   &s.islands_primal,
                   &s.newton_iterations,
                   &s.pcg_iterations,
                   &s.newton_factorizations,
                   &s.islands,
                   &s.rigid_bodies_coupled};
  for (int k = 0; k < 16; ++k) *counts[k] = seed * 100 + k;
  double* worst[] = {&s.violation_before, &s.violation_after,     &s.stationarity, &s.lcp_residual,
                     &s.kkt_primal,       &s.kkt_complementarity, &s.kkt_dual};
  for (int k = 0; k < 7; ++k) *worst[k] = (k % 2 == seed % 2) ? 1e-3 * (k + 1) : 1e-6 * (k + 1);
  for (int i = 0; i < kNumRowTypes; ++i) {
    s.kkt_primal_by_type[i] = (i % 2 == seed % 2) ? 2e-3 : 2e-6;
    s.kkt_complementarity_by_type[i] = (i % 2 == seed % 2) ? 3e-6 : 3e-3;
  }
  s.converged = converged;
  return s;
}

TEST(StepStatsMergeTest, SubstepsAddTimesAndCountsAndKeepTheWorstResiduals) {
  const StepStats a = MakeStats(1, true), b = MakeStats(2, false);
  StepStats call;
  call.substeps = 0;
  AddSubstepStats(a, call);
  EXPECT_TRUE(call.converged);
  AddSubstepStats(b, call);
  EXPECT_EQ(call.substeps, 2);
  EXPECT_FALSE(call.converged);
  EXPECT_EQ(call.ms_total, a.ms_total + b.ms_total);
  EXPECT_EQ(call.ms_rigid, a.ms_rigid + b.ms_rigid);
  EXPECT_EQ(call.ms_unconstrained, a.ms_unconstrained + b.ms_unconstrained);
  EXPECT_EQ(call.ms_rows, a.ms_rows + b.ms_rows);
  EXPECT_EQ(call.ms_solve, a.ms_solve + b.ms_solve);
  EXPECT_EQ(call.ms_integrate, a.ms_integrate + b.ms_integrate);
  EXPECT_EQ(call.ms_stage_begin_steps, a.ms_stage_begin_steps + b.ms_stage_begin_steps);
  EXPECT_EQ(call.ms_stage_partners, a.ms_stage_partners + b.ms_stage_partners);
  EXPECT_EQ(call.ms_stage_islands, a.ms_stage_islands + b.ms_stage_islands);
  EXPECT_EQ(call.ms_stage_couple_rigid, a.ms_stage_couple_rigid + b.ms_stage_couple_rigid);
  EXPECT_EQ(call.ms_stage_row_sources, a.ms_stage_row_sources + b.ms_stage_row_sources);
  EXPECT_EQ(call.ms_stage_bullet_solver, a.ms_stage_bullet_solver + b.ms_stage_bullet_solver);
  EXPECT_EQ(call.ms_stage_solve_islands, a.ms_stage_solve_islands + b.ms_stage_solve_islands);
  EXPECT_EQ(call.ms_stage_end_steps, a.ms_stage_end_steps + b.ms_stage_end_steps);
  EXPECT_EQ(call.rows_total(), a.rows_total() + b.rows_total());
  EXPECT_EQ(call.rows_joint, a.rows_joint + b.rows_joint);
  EXPECT_EQ(call.pgs_sweeps, a.pgs_sweeps + b.pgs_sweeps);
  EXPECT_EQ(call.active_set_solves, a.active_set_solves + b.active_set_solves);
  EXPECT_EQ(call.sqp_iterations, a.sqp_iterations + b.sqp_iterations);
  EXPECT_EQ(call.restoration_iterations, a.restoration_iterations + b.restoration_iterations);
  EXPECT_EQ(call.islands_dual, a.islands_dual + b.islands_dual);
  EXPECT_EQ(call.islands_primal, a.islands_primal + b.islands_primal);
  EXPECT_EQ(call.newton_iterations, a.newton_iterations + b.newton_iterations);
  EXPECT_EQ(call.pcg_iterations, a.pcg_iterations + b.pcg_iterations);
  EXPECT_EQ(call.newton_factorizations, a.newton_factorizations + b.newton_factorizations);
  EXPECT_EQ(call.islands, a.islands + b.islands);
  EXPECT_EQ(call.rigid_bodies_coupled, a.rigid_bodies_coupled + b.rigid_bodies_coupled);
  EXPECT_EQ(call.violation_before, std::max(a.violation_before, b.violation_before));
  EXPECT_EQ(call.violation_after, std::max(a.violation_after, b.violation_after));
  EXPECT_EQ(call.stationarity, std::max(a.stationarity, b.stationarity));
  EXPECT_EQ(call.lcp_residual, std::max(a.lcp_residual, b.lcp_residual));
  EXPECT_EQ(call.kkt_primal, std::max(a.kkt_primal, b.kkt_primal));
  EXPECT_EQ(call.kkt_complementarity, std::max(a.kkt_complementarity, b.kkt_complementarity));
  EXPECT_EQ(call.kkt_dual, std::max(a.kkt_dual, b.kkt_dual));
  for (int i = 0; i < kNumRowTypes; ++i) {
    EXPECT_EQ(call.kkt_primal_by_type[i], 2e-3);
    EXPECT_EQ(call.kkt_complementarity_by_type[i], 3e-3);
  }
}

TEST(StepStatsMergeTest, IslandsAddTheirWorkAndKeepTheMostSqpIterations) {
  const StepStats a = MakeStats(3, true), b = MakeStats(1, true);
  StepStats step;
  AddIslandStats(a, step);
  AddIslandStats(b, step);
  EXPECT_EQ(step.sqp_iterations, a.sqp_iterations);  // the slowest island, not the sum
  EXPECT_EQ(step.ms_solve, a.ms_solve + b.ms_solve);
  EXPECT_EQ(step.rows_total(), a.rows_total() + b.rows_total());
  EXPECT_EQ(step.kkt_dual, std::max(a.kkt_dual, b.kkt_dual));
  // The world's own timers and counts are not the islands'.
  EXPECT_EQ(step.ms_total, 0.0);
  EXPECT_EQ(step.ms_stage_solve_islands, 0.0);
  EXPECT_EQ(step.islands, 0);
  EXPECT_EQ(step.substeps, 1);
}

// The README's strain-limited cantilever, clamped at x = 0 and sagging under gravity.
struct CantileverWorld {
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher{&configuration};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  DeformableWorld world{&dispatcher, &broadphase, &solver, &configuration};
  DeformableBody* beam = nullptr;
  std::vector<StepStats> substeps;  // last_step_stats() of every finished substep

  CantileverWorld() {
    world.setGravity(btVector3(0, 0, -9.81));
    DeformableBodySettings settings;
    settings.name = "beam";
    settings.material = {200e3, 0.3, 1000.0};
    beam = world.AddTetBody(MakeBoxTetMesh(Vec3(1, 0.2, 0.2), 10, 2, 2), settings);
    beam->FixNodesWhere([](const Vec3& X) { return X.x() < 1e-9; });
    world.SetStrainLimits(beam, StrainLimitSettings::Isotropic(0.96, 1.04));
  }
  // Records every substep's final stats: before a substep begins, last_step_stats() still holds
  // the previous substep's, ms_total included.
  void RecordSubsteps() { world.setInternalTickCallback(&RecordPrevious, this, true); }
  static void RecordPrevious(btDynamicsWorld* world, btScalar) {
    auto* self = static_cast<CantileverWorld*>(world->getWorldUserInfo());
    self->substeps.push_back(self->world.last_step_stats());
  }
};

TEST(DeformableWorldCallStatsTest, OneCallOfFourSubstepsSumsTheFourSubstepsStats) {
  CantileverWorld scene;
  for (int call = 0; call < 8; ++call) scene.world.stepSimulation(1.0 / 60.0, 4, 1.0 / 240.0);
  scene.RecordSubsteps();
  scene.world.stepSimulation(1.0 / 60.0, 4, 1.0 / 240.0);
  ASSERT_EQ(scene.substeps.size(), 4u);  // the previous call's last substep, then 1..3
  scene.substeps.erase(scene.substeps.begin());
  scene.substeps.push_back(scene.world.last_step_stats());
  const StepStats& call = scene.world.last_call_stats();
  ASSERT_EQ(call.substeps, 4);
  double ms_total = 0.0, ms_solve = 0.0, ms_stage_solve = 0.0, violation_after = 0.0;
  int rows = 0, sqp = 0, pgs = 0, newton = 0;
  bool converged = true;
  for (const StepStats& s : scene.substeps) {
    ms_total += s.ms_total;
    ms_solve += s.ms_solve;
    ms_stage_solve += s.ms_stage_solve_islands;
    violation_after = std::max(violation_after, s.violation_after);
    rows += s.rows_total();
    sqp += s.sqp_iterations;
    pgs += s.pgs_sweeps;
    newton += s.newton_iterations;
    converged = converged && s.converged;
  }
  EXPECT_EQ(call.ms_total, ms_total);
  EXPECT_EQ(call.ms_solve, ms_solve);
  EXPECT_EQ(call.ms_stage_solve_islands, ms_stage_solve);
  EXPECT_EQ(call.violation_after, violation_after);
  EXPECT_EQ(call.rows_total(), rows);
  EXPECT_EQ(call.sqp_iterations, sqp);
  EXPECT_EQ(call.pgs_sweeps, pgs);
  EXPECT_EQ(call.newton_iterations, newton);
  EXPECT_EQ(call.converged, converged);
  // The beam sags past its limits by now, so there is constraint work to add up.
  EXPECT_GT(rows, 0);
  EXPECT_GT(call.ms_total, scene.world.last_step_stats().ms_total);
}

TEST(DeformableWorldCallStatsTest, OneCallOfFourSubstepsEqualsFourCallsOfOne) {
  CantileverWorld once, four;
  for (int call = 0; call < 9; ++call) {
    once.world.stepSimulation(1.0 / 60.0, 4, 1.0 / 240.0);
    ASSERT_EQ(once.world.last_call_stats().substeps, 4);
    StepStats sum;
    sum.substeps = 0;
    for (int k = 0; k < 4; ++k) {
      four.world.stepSimulation(1.0 / 240.0, 1, 1.0 / 240.0);
      ASSERT_EQ(four.world.last_call_stats().substeps, 1);
      AddSubstepStats(four.world.last_call_stats(), sum);
    }
    const StepStats& c = once.world.last_call_stats();
    ASSERT_EQ(c.rows_strain, sum.rows_strain) << "call " << call;
    ASSERT_EQ(c.sqp_iterations, sum.sqp_iterations);
    ASSERT_EQ(c.pgs_sweeps, sum.pgs_sweeps);
    ASSERT_EQ(c.newton_iterations, sum.newton_iterations);
    ASSERT_EQ(c.islands, sum.islands);
    ASSERT_EQ(c.violation_after, sum.violation_after);
    ASSERT_EQ(c.kkt_primal, sum.kkt_primal);
    ASSERT_EQ(c.converged, sum.converged);
    ASSERT_EQ(once.beam->x(), four.beam->x());
  }
  EXPECT_GT(once.world.last_call_stats().rows_strain, 0);
}

TEST(DeformableWorldCallStatsTest, CallThatOnlyAccumulatesTimeHasNoSubsteps) {
  CantileverWorld scene;
  scene.world.stepSimulation(1.0 / 480.0, 4, 1.0 / 240.0);  // half a substep: none runs
  EXPECT_EQ(scene.world.last_call_stats().substeps, 0);
  EXPECT_EQ(scene.world.last_call_stats().ms_total, 0.0);
  scene.world.stepSimulation(1.0 / 480.0, 4, 1.0 / 240.0);  // the other half: one substep
  EXPECT_EQ(scene.world.last_call_stats().substeps, 1);
}

}  // namespace
}  // namespace taut
