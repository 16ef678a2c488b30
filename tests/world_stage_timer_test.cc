// DeformableWorld's stage timers (StepStats::ms_stage_*, docs/architecture.md §3): filled every
// substep, never negative, summing to at most the substep's time, and consistent with the coarse
// timers they feed.
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "demos/scenes/bullet_world_holder.h"
#include "plugin/box_tet_mesher.h"

namespace taut {
namespace {

// The stage timers of `stats` in stage order.
std::vector<double> StageTimes(const StepStats& stats) {
  return {stats.ms_stage_begin_steps,   stats.ms_stage_partners,    stats.ms_stage_islands,
          stats.ms_stage_couple_rigid,  stats.ms_stage_row_sources, stats.ms_stage_bullet_solver,
          stats.ms_stage_solve_islands, stats.ms_stage_end_steps};
}

TEST(WorldStageTimerTest, StageTimersAreFilledNonNegativeAndSumToAtMostTheStep) {
  // A soft block on the ground with a rigid box on it (a coupled island) and a box elsewhere (a
  // rigid-only island), so every stage has work.
  BulletWorldHolder holder;
  holder.AddStaticGround(1.0);
  DeformableBodySettings settings;
  settings.name = "block";
  settings.material = {2e5, 0.3, 1000.0};
  settings.mass_damping = 2.0;
  holder.world.AddTetBody(MakeBoxTetMesh(Vec3(0.4, 0.4, 0.2), 4, 4, 2, Vec3(0, 0, 0.1)), settings);
  holder.AddRigidBody(std::make_unique<btBoxShape>(btVector3(0.1, 0.1, 0.05)), 1.0,
                      btVector3(0, 0, 0.26));
  holder.AddRigidBody(std::make_unique<btBoxShape>(btVector3(0.1, 0.1, 0.1)), 1.0,
                      btVector3(2, 0, 0.1));
  double sum_over_steps = 0.0;
  for (int i = 0; i < 60; ++i) {
    holder.world.stepSimulation(1.0 / 240.0, 1, 1.0 / 240.0);
    const StepStats& stats = holder.world.last_step_stats();
    double sum = 0.0;
    for (double ms : StageTimes(stats)) {
      EXPECT_GE(ms, 0.0) << "step " << i;
      sum += ms;
    }
    EXPECT_LE(sum, stats.ms_total) << "step " << i;
    // The coarse timers are sums of stage timers.
    EXPECT_EQ(stats.ms_unconstrained, stats.ms_stage_begin_steps);
    EXPECT_EQ(stats.ms_integrate, stats.ms_stage_end_steps);
    EXPECT_GE(stats.ms_rows, stats.ms_stage_partners + stats.ms_stage_islands +
                                 stats.ms_stage_couple_rigid + stats.ms_stage_row_sources);
    sum_over_steps += sum;
  }
  // The clock ticks: the stages took measurable time over the run, the unconstrained step too.
  EXPECT_GT(sum_over_steps, 0.0);
  EXPECT_GT(holder.world.last_step_stats().ms_stage_begin_steps, 0.0);
  EXPECT_GT(holder.world.last_step_stats().rigid_bodies_coupled, 0);
}

TEST(WorldStageTimerTest, WithoutDeformableBodiesTheStageTimersStayZero) {
  BulletWorldHolder holder;
  holder.AddStaticGround(1.0);
  holder.AddRigidBody(std::make_unique<btBoxShape>(btVector3(0.1, 0.1, 0.1)), 1.0,
                      btVector3(0, 0, 0.1));
  holder.world.stepSimulation(1.0 / 240.0, 1, 1.0 / 240.0);
  for (double ms : StageTimes(holder.world.last_step_stats())) EXPECT_EQ(ms, 0.0);
}

}  // namespace
}  // namespace taut
