// Deformable bodies against Bullet's static shapes: normal rows keep nodes out of the ground,
// friction rows on the Coulomb disk decide stick and slip.
#include <gtest/gtest.h>

#include <cmath>

#include "bullet_bridge/eigen_bullet.h"
#include "demos/scenes/bullet_world_holder.h"
#include "plugin/box_tet_mesher.h"

namespace taut {
namespace {

// A soft 0.2 m cube above a static ground plane z = 0 (plane friction 1).
struct CubeOnGround {
  BulletWorldHolder holder;
  btStaticPlaneShape plane{btVector3(0, 0, 1), 0};
  std::unique_ptr<btRigidBody> ground;
  DeformableBody* cube = nullptr;

  CubeOnGround(double friction, double height, const btVector3& gravity) {
    btRigidBody::btRigidBodyConstructionInfo info(0.0, nullptr, &plane);
    ground = std::make_unique<btRigidBody>(info);
    ground->setFriction(1.0);
    holder.world.addRigidBody(ground.get());
    holder.world.setGravity(gravity);
    DeformableBodySettings settings;
    settings.name = "cube";
    settings.material = {5e4, 0.3, 500.0};
    settings.mass_damping = 0.5;
    settings.friction = friction;
    cube = holder.world.AddTetBody(
        MakeBoxTetMesh(Vec3(0.2, 0.2, 0.2), 2, 2, 2, Vec3(-0.1, -0.1, height)), settings);
  }
  ~CubeOnGround() { holder.world.removeRigidBody(ground.get()); }
  void Run(int steps) {
    for (int i = 0; i < steps; ++i) holder.world.stepSimulation(1.0 / 240.0, 1, 1.0 / 240.0);
  }
  double MinZ() const {
    double z = 1e9;
    for (int i = 0; i < cube->num_nodes(); ++i) z = std::min(z, cube->node_position(i).z());
    return z;
  }
  double MeanX() const {
    double x = 0.0;
    for (int i = 0; i < cube->num_nodes(); ++i) x += cube->node_position(i).x();
    return x / cube->num_nodes();
  }
};

TEST(RigidContactTest, DroppedCubeComesToRestOnTheGroundWithoutSinkingIn) {
  CubeOnGround scene(0.5, 0.1, btVector3(0, 0, -9.81));
  double deepest = 0.0;
  for (int i = 0; i < 240; ++i) {
    scene.Run(1);
    deepest = std::min(deepest, scene.MinZ());
  }
  std::printf("dropped cube: deepest node %.2e m, rest height %.4f m, contact rows %d\n", deepest,
              scene.MinZ(), scene.holder.world.last_step_stats().rows_contact);
  EXPECT_GT(deepest, -2e-3);      // penetration below 2 mm even at the 1.4 m/s impact
  EXPECT_LT(scene.MinZ(), 0.01);  // it did land
  EXPECT_GT(scene.holder.world.last_step_stats().rows_contact, 0);
  EXPECT_LT(scene.cube->v().norm() / std::sqrt(scene.cube->num_nodes()), 0.05);  // at rest
}

// Gravity tilted by 30 degrees = a 30 degree incline (tan 30 = 0.577) down +x.
constexpr double kInclineAngle = M_PI / 6.0;
// A cube with friction coefficient mu resting 0.5 mm above that incline.
struct CubeOnIncline : CubeOnGround {
  explicit CubeOnIncline(double mu)
      : CubeOnGround(
            mu, 0.0005,
            btVector3(9.81 * std::sin(kInclineAngle), 0, -9.81 * std::cos(kInclineAngle))) {}
};

TEST(RigidContactTest, FrictionSticksBelowTheConeAndSlidesAboveIt) {
  const double theta = kInclineAngle;
  CubeOnIncline sticky(1.0), slippery(0.1);
  const double x0 = sticky.MeanX();
  sticky.Run(120);
  slippery.Run(120);
  const double stick = sticky.MeanX() - x0, slide = slippery.MeanX() - x0;
  // Sliding block: a = g (sin - mu cos) = 4.06 m/s^2 -> 0.51 m in 0.5 s.
  const double expected = 0.5 * 9.81 * (std::sin(theta) - 0.1 * std::cos(theta)) * 0.25;
  std::printf(
      "incline 30 deg, 0.5 s: mu = 1 moves %.4f m, mu = 0.1 moves %.4f m (rigid block "
      "%.4f m)\n",
      stick, slide, expected);
  EXPECT_LT(stick, 0.02);
  EXPECT_NEAR(slide, expected, 0.25 * expected);
  EXPECT_GT(slippery.MinZ(), -2e-3);
}

TEST(RigidContactTest, FrictionlessContactSlidesFreelyOnNormalRowsAlone) {
  // mu = 0 on the 30 degree incline: the block slides as if no friction rows existed
  // (a = g sin 30 = 4.9 m/s^2 -> 0.61 m in 0.5 s), and each contact has its normal row only.
  const double theta = kInclineAngle;
  CubeOnIncline frictionless(0.0), rough(0.1);
  const double x0 = frictionless.MeanX();
  frictionless.Run(120);
  rough.Run(120);
  const double slide = frictionless.MeanX() - x0;
  const double expected = 0.5 * 9.81 * std::sin(theta) * 0.25;
  const int normal_rows = frictionless.holder.world.last_step_stats().rows_contact;
  const int rough_rows = rough.holder.world.last_step_stats().rows_contact;
  std::printf(
      "incline 30 deg, mu = 0: moves %.4f m in 0.5 s (rigid block %.4f m), %d rows; "
      "mu = 0.1: %d rows\n",
      slide, expected, normal_rows, rough_rows);
  EXPECT_NEAR(slide, expected, 0.25 * expected);
  EXPECT_GT(slide, rough.MeanX() - x0);
  EXPECT_GT(normal_rows, 0);
  EXPECT_EQ(rough_rows, 3 * normal_rows);
  EXPECT_GT(frictionless.MinZ(), -2e-3);
}

}  // namespace
}  // namespace taut

namespace taut {
namespace {

// A kinematic rigid "bone" lifts soft flesh pinned to it: the pinned nodes follow the bone's
// frame exactly, the rest of the body hangs below and follows.
TEST(RigidAttachmentTest, KinematicBoneDrivesPinnedSoftFlesh) {
  BulletWorldHolder holder;
  btBoxShape bone_shape(btVector3(0.1, 0.1, 0.02));
  btDefaultMotionState bone_state(btTransform(btQuaternion::getIdentity(), btVector3(0, 0, 0.22)));
  btRigidBody bone(0.0, &bone_state, &bone_shape);
  bone.setCollisionFlags(bone.getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
  bone.setActivationState(DISABLE_DEACTIVATION);
  holder.world.addRigidBody(&bone);
  DeformableBodySettings settings;
  settings.material = {2e4, 0.3, 500.0};
  settings.mass_damping = 2.0;
  DeformableBody* flesh = holder.world.AddTetBody(
      MakeBoxTetMesh(Vec3(0.2, 0.2, 0.2), 2, 2, 2, Vec3(-0.1, -0.1, 0)), settings);
  std::vector<int> top;
  for (int i = 0; i < flesh->num_nodes(); ++i)
    if (flesh->node_position(i).z() > 0.2 - 1e-9) top.push_back(i);
  holder.world.AttachNodesToRigidBody(flesh, top, &bone);
  // Lift the bone 0.5 m and turn it 30 degrees about z over 1 s (60 frames).
  for (int frame = 1; frame <= 60; ++frame) {
    const double t = frame / 60.0;
    bone_state.setWorldTransform(btTransform(btQuaternion(btVector3(0, 0, 1), t * M_PI / 6),
                                             btVector3(0, 0, 0.22 + 0.5 * t)));
    holder.world.stepSimulation(1.0 / 60.0, 4, 1.0 / 240.0);
  }
  const btTransform& pose = bone.getWorldTransform();
  const btTransform initial(btQuaternion::getIdentity(), btVector3(0, 0, 0.22));
  for (int i : top) {
    const btVector3 rest = ToBullet(flesh->model().rest_positions().segment<3>(3 * i));
    const Vec3 expected = ToEigen(pose * (initial.inverse() * rest));
    EXPECT_LT((flesh->node_position(i) - expected).norm(), 1e-9) << "node " << i;
  }
  double lowest = 1e9;
  for (int i = 0; i < flesh->num_nodes(); ++i)
    lowest = std::min(lowest, flesh->node_position(i).z());
  EXPECT_GT(lowest, 0.3);  // the whole body came up with the bone
  holder.world.removeRigidBody(&bone);
}

}  // namespace
}  // namespace taut
