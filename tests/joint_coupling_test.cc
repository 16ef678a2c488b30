// Bullet joints on a rigid body that touches a deformable: the joint rows join the deformable's
// island and hold in the same solve (a bar pinned at one end, resting on a soft block).
#include <gtest/gtest.h>

#include "bullet_bridge/eigen_bullet.h"
#include "demos/scenes/bullet_world_holder.h"
#include "plugin/box_tet_mesher.h"

namespace taut {
namespace {

TEST(JointCouplingTest, PinnedBarRestingOnASoftBlockKeepsItsPivot) {
  BulletWorldHolder holder;
  holder.AddStaticGround(1.0);
  DeformableBodySettings settings;
  settings.name = "block";
  settings.material = {2e5, 0.3, 1000.0};
  settings.mass_damping = 2.0;
  DeformableBody* block = holder.world.AddTetBody(
      MakeBoxTetMesh(Vec3(0.4, 0.2, 0.2), 4, 2, 2, Vec3(0.1, -0.1, 0.0)), settings);
  btRigidBody* bar = holder.AddRigidBody(std::make_unique<btBoxShape>(btVector3(0.5, 0.05, 0.05)),
                                         5.0, btVector3(0, 0, 0.25));
  // Pin the bar's left end to the world at (-0.5, 0, 0.25).
  const btVector3 pivot_local(-0.5, 0, 0);
  btPoint2PointConstraint pin(*bar, pivot_local);
  holder.world.addConstraint(&pin, true);
  double worst_drift = 0.0;
  int joint_rows = 0;
  for (int i = 0; i < 240; ++i) {
    holder.world.stepSimulation(1.0 / 240.0, 1, 1.0 / 240.0);
    const btVector3 pivot = bar->getWorldTransform() * pivot_local;
    worst_drift =
        std::max(worst_drift, static_cast<double>((pivot - btVector3(-0.5, 0, 0.25)).length()));
    joint_rows = std::max(joint_rows, holder.world.last_step_stats().rows_joint);
  }
  double top = -HUGE_VAL;
  for (int i = 0; i < block->num_nodes(); ++i) top = std::max(top, block->node_position(i).z());
  const double tip_z =
      static_cast<double>((bar->getWorldTransform() * btVector3(0.5, 0, -0.05)).z());
  std::printf(
      "pinned bar on a soft block: pivot drift %.2e m, joint rows %d, coupled %d, bar tip "
      "bottom %.4f m, block top %.4f m\n",
      worst_drift, joint_rows, holder.world.last_step_stats().rigid_bodies_coupled, tip_z, top);
  EXPECT_EQ(holder.world.last_step_stats().rigid_bodies_coupled, 1);
  EXPECT_EQ(joint_rows, 3);  // point-to-point: three rows, solved in the island
  EXPECT_LT(worst_drift, 2e-3);
  EXPECT_GT(tip_z, 0.15);  // the block holds the bar's far end up (it would swing down to ~-0.25)
  holder.world.removeConstraint(&pin);
}

}  // namespace
}  // namespace taut
