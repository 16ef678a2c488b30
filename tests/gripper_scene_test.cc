// Articulated robots coupled with deformables (DeformableMultiBodyWorld, demos/scenes/
// gripper_scene.h): a two-finger btMultiBody gripper with prismatic joint motors squeezes a soft,
// strain-limited tet cube and lifts it 5 cm off the ground, on both island solver paths. The
// forces close the loop both ways: each finger presses with its motor's force limit and the
// fingers' friction carries the cube's weight.
#include "demos/scenes/gripper_scene.h"

#include <gtest/gtest.h>

#include <cstdio>

namespace taut {
namespace {

constexpr double kGripperStep = 1.0 / 240.0;
constexpr int kSteps = 288;  // 0.4 s grip, 0.5 s lift at 0.1 m/s, 0.3 s hold

// Sum of the last substep's contact forces on the cube from finger f's collider [N].
Vec3 SumFingerForce(GripperScene& scene, int f) {
  const btCollisionObject* finger = scene.rig().body->getLinkCollider(1 + f);
  Vec3 sum = Vec3::Zero();
  for (const DeformableContactPoint& c : scene.multibody_world().last_contacts(&scene.cube()))
    if (c.partner_object == finger) sum += c.force;
  return sum;
}

// Lowest node of the cube [m].
double CalcCubeBottom(const DeformableBody& cube) {
  double z = 1e9;
  for (int i = 0; i < cube.num_nodes(); ++i) z = std::min(z, cube.node_position(i).z());
  return z;
}

class GripperSceneTest : public ::testing::TestWithParam<IslandSolverKind> {};

TEST_P(GripperSceneTest, SqueezesTheStrainLimitedCubeAndLiftsItOffTheGround) {
  GripperScene scene;
  scene.mutable_solver_settings().solver = GetParam();
  const GripperScene::Settings settings;
  Vec3 grip_force[2] = {Vec3::Zero(), Vec3::Zero()};
  for (int s = 0; s < kSteps; ++s) {
    scene.Step(kGripperStep);
    // Averages over the last 0.1 s of the grip and of the hold.
    if (s >= 72 && s < 96)
      for (int f = 0; f < 2; ++f) grip_force[f] += SumFingerForce(scene, f) / 24.0;
  }
  Vec3 hold_force[2] = {SumFingerForce(scene, 0), SumFingerForce(scene, 1)};
  const double lift = scene.lift_height();
  const double rise = scene.com_rise();
  const Vec3 com = scene.CalcCubeCenterOfMass();
  const double gap = scene.finger_face(1) - scene.finger_face(0);
  const double weight = scene.cube().mass().sum() * 9.81;
  std::printf(
      "[ gripper %s ] lift %.5f m, COM rise %.5f m, slip %.2e m, bottom %.4f m, gap %.4f m, "
      "grip forces x %.3f %.3f N (motor %.1f N), hold forces z %.4f + %.4f = %.4f N "
      "(weight %.4f N)\n",
      GetIslandSolverName(GetParam()), lift, rise, scene.slip(), CalcCubeBottom(scene.cube()), gap,
      grip_force[0].x(), -grip_force[1].x(), settings.squeeze_force, hold_force[0].z(),
      hold_force[1].z(), hold_force[0].z() + hold_force[1].z(), weight);
  // The carriage lifted 5 cm and the cube came along within 2 mm of slip, off the ground.
  EXPECT_NEAR(lift, settings.lift_speed * settings.lift_time, 1e-3);
  EXPECT_GT(rise, 0.048);
  EXPECT_LT(std::abs(scene.slip()), 2e-3);
  EXPECT_GT(CalcCubeBottom(scene.cube()), 0.045);
  // It stays between the fingers, centred.
  EXPECT_GT(com.x(), scene.finger_face(0));
  EXPECT_LT(com.x(), scene.finger_face(1));
  EXPECT_LT(std::abs(com.x()), 5e-3);
  EXPECT_LT(std::abs(com.y()), 5e-3);
  // The squeeze is strain-limited: compressed to at most 10 % (stretch >= 0.9), to within 1 mm.
  EXPECT_GT(gap, settings.strain_min * settings.cube_side - 1e-3);
  EXPECT_LT(gap, settings.cube_side);
  // Two-way: while gripping on the ground each finger presses with its motor's limit, +x from
  // the left finger, -x from the right ...
  EXPECT_NEAR(grip_force[0].x(), settings.squeeze_force, 0.03 * settings.squeeze_force);
  EXPECT_NEAR(-grip_force[1].x(), settings.squeeze_force, 0.03 * settings.squeeze_force);
  // ... and, lifted and at rest, the fingers' friction carries the cube's weight (1 %).
  EXPECT_NEAR(hold_force[0].z() + hold_force[1].z(), weight, 0.01 * weight);
}

// Steps `scene` until `stop(stats)` holds; returns that step's index (kSteps if none did).
template <typename Stop>
int StepUntil(GripperScene& scene, Stop stop) {
  int step = 0;
  for (; step < kSteps; ++step) {
    scene.Step(kGripperStep);
    if (stop(scene.last_step_stats())) break;
  }
  return step;
}

// The next `count` steps after `step` are certified on the dual path, without retries.
void ExpectDualSteps(GripperScene& scene, int step, int count) {
  for (int next = 0; next < count; ++next) {
    scene.Step(kGripperStep);
    const StepStats& stats = scene.last_step_stats();
    EXPECT_EQ(stats.islands_primal, 0) << "step " << step + 1 + next;
    EXPECT_EQ(stats.islands_retried, 0) << "step " << step + 1 + next;
    EXPECT_TRUE(stats.converged) << "step " << step + 1 + next;
  }
}

// On the auto path the gripper's island takes the primal path by its rows per DOF. Capped at one
// multiplier iteration, that path fails at first contact and the dual retry certifies the step.
// The island then stays on the dual path (IslandSolver::kDualStepsAfterPrimalFailure) instead of
// failing again, as it did at 50-110 ms a step before that rule (then uncapped: the primal path
// failed there until its certificate fitted friction to the current Coulomb disks).
TEST(GripperSceneAutoTest, AfterAPrimalFailureTheDualRetryCertifiedTheIslandStaysDual) {
  GripperScene scene;
  scene.mutable_solver_settings().solver = IslandSolverKind::kAuto;
  scene.mutable_solver_settings().primal.max_iterations = 1;
  const int step = StepUntil(scene, [](const StepStats& stats) {
    return stats.islands_retried > 0 && stats.islands_dual > 0 && stats.converged;
  });
  std::printf("first primal failure certified by the dual retry at step %d\n", step);
  ASSERT_LT(step, kSteps) << "no step was retried onto the dual path";
  ExpectDualSteps(scene, step, 10);
}

// Uncapped, the gripper's primal steps certify but take about 9 Newton iterations each, where the
// dual path is cheaper (docs/solver.md, "Two paths"): after the first such step the island goes to
// the dual path (IslandSolver::kCostlyPrimalNewtonIterations), certified, for the next steps.
TEST(GripperSceneAutoTest, ACostlyCertifiedPrimalStepSendsTheIslandToTheDualPath) {
  GripperScene scene;
  scene.mutable_solver_settings().solver = IslandSolverKind::kAuto;
  const int step = StepUntil(scene, [](const StepStats& stats) {
    return stats.islands_primal > 0 && stats.converged &&
           stats.newton_iterations > IslandSolver::kCostlyPrimalNewtonIterations;
  });
  std::printf("first costly certified primal step: %d\n", step);
  ASSERT_LT(step, kSteps) << "no primal step took more than the costly count";
  ExpectDualSteps(scene, step, 10);
}

INSTANTIATE_TEST_SUITE_P(BothPaths, GripperSceneTest,
                         ::testing::Values(IslandSolverKind::kDual, IslandSolverKind::kPrimal),
                         [](const auto& info) {
                           return std::string(GetIslandSolverName(info.param));
                         });

}  // namespace
}  // namespace taut
