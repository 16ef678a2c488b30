#include "bullet_bridge/deformable_world.h"

#include <btBulletDynamicsCommon.h>
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "plugin/box_tet_mesher.h"

namespace taut {
namespace {

// A world of type W with a ground plane, a sphere, a box stack and a hinge, stepped N times.
template <typename World>
struct RigidScene {
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher{&configuration};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  World world{&dispatcher, &broadphase, &solver, &configuration};
  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  std::vector<std::unique_ptr<btDefaultMotionState>> states;
  std::vector<std::unique_ptr<btRigidBody>> bodies;
  std::unique_ptr<btHingeConstraint> hinge;

  btRigidBody* Add(btCollisionShape* shape, double mass, const btVector3& position) {
    shapes.emplace_back(shape);
    btVector3 inertia(0, 0, 0);
    if (mass > 0) shape->calculateLocalInertia(mass, inertia);
    states.push_back(
        std::make_unique<btDefaultMotionState>(btTransform(btQuaternion(0.1, 0.2, 0.3), position)));
    bodies.push_back(std::make_unique<btRigidBody>(mass, states.back().get(), shape, inertia));
    world.addRigidBody(bodies.back().get());
    return bodies.back().get();
  }

  RigidScene() {
    world.setGravity(btVector3(0, 0, -9.81));
    Add(new btStaticPlaneShape(btVector3(0, 0, 1), 0), 0, btVector3(0, 0, 0));
    Add(new btSphereShape(0.3), 2.0, btVector3(0.1, 0, 2));
    for (int i = 0; i < 3; ++i)
      Add(new btBoxShape(btVector3(0.2, 0.2, 0.2)), 1.0, btVector3(1, 0, 0.3 + 0.5 * i));
    btRigidBody* a = Add(new btCapsuleShape(0.1, 0.5), 1.0, btVector3(-1, 0, 1.5));
    hinge = std::make_unique<btHingeConstraint>(*a, btVector3(0, 0.4, 0), btVector3(1, 0, 0));
    world.addConstraint(hinge.get());
  }
  ~RigidScene() {
    world.removeConstraint(hinge.get());
    for (auto& body : bodies) world.removeRigidBody(body.get());
  }
};

TEST(DeformableWorldTest, PureRigidSceneIsBitIdenticalToStockBullet) {
  RigidScene<btDiscreteDynamicsWorld> stock;
  RigidScene<DeformableWorld> ours;
  for (int step = 0; step < 300; ++step) {
    stock.world.stepSimulation(1.0 / 60.0, 4, 1.0 / 240.0);
    ours.world.stepSimulation(1.0 / 60.0, 4, 1.0 / 240.0);
    for (size_t b = 0; b < stock.bodies.size(); ++b) {
      const btTransform& s = stock.bodies[b]->getWorldTransform();
      const btTransform& o = ours.bodies[b]->getWorldTransform();
      ASSERT_EQ(s.getOrigin(), o.getOrigin()) << "step " << step << " body " << b;
      ASSERT_EQ(s.getRotation(), o.getRotation()) << "step " << step << " body " << b;
      ASSERT_EQ(stock.bodies[b]->getLinearVelocity(), ours.bodies[b]->getLinearVelocity());
    }
  }
  // The scene really moved (the sphere fell onto the ground).
  EXPECT_LT(ours.bodies[1]->getWorldTransform().getOrigin().z(), 0.5);
}

TEST(DeformableWorldTest, DeformableBodyFallsInsideSubstepsAndRefreshesItsAabb) {
  RigidScene<DeformableWorld> scene;
  DeformableBodySettings settings;
  settings.name = "cube";
  settings.material = {1e5, 0.3, 1000};
  DeformableBody* body =
      scene.world.AddTetBody(MakeBoxTetMesh(Vec3(0.2, 0.2, 0.2), 2, 2, 2, Vec3(5, 5, 5)), settings);
  EXPECT_EQ(scene.world.num_deformable_bodies(), 1);
  // 1/60 s in 4 substeps of 1/240 s: free fall z = 5 - g t^2 / 2 (backward Euler: slightly less).
  scene.world.stepSimulation(1.0 / 60.0, 4, 1.0 / 240.0);
  const double expected_drop = 0.5 * 9.81 / 3600.0;
  const double drop = 5.0 - body->node_position(0).z();
  EXPECT_NEAR(drop, expected_drop, 0.3 * expected_drop);
  EXPECT_GT(drop, 0.0);
  // Bullet's broadphase AABB follows the body.
  btVector3 lo, hi;
  scene.world.getBroadphase()->getAabb(
      scene.world.getCollisionObjectArray()[scene.world.getNumCollisionObjects() - 1]
          ->getBroadphaseHandle(),
      lo, hi);
  EXPECT_LT(lo.z(), 5.0 - drop + 1e-6);
  // Top of the cube plus the shape margin (0.01 m) and Bullet's broadphase slack.
  EXPECT_GT(hi.z(), 5.2 - drop);
  EXPECT_LT(hi.z(), 5.2 - drop + 0.05);
  EXPECT_GT(scene.world.last_step_stats().ms_total, 0.0);
  scene.world.RemoveDeformableBody(body);
  EXPECT_EQ(scene.world.num_deformable_bodies(), 0);
}

TEST(DeformableWorldTest, OneBodyFailingItsStepLeavesEveryBodyAtTheLastGoodState) {
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher(&configuration);
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  DeformableWorld world(&dispatcher, &broadphase, &solver, &configuration);
  world.setGravity(btVector3(0, 0, -9.81));
  DeformableBodySettings settings;
  settings.material = {1e5, 0.3, 1000.0};
  settings.name = "good";
  DeformableBody* good =
      world.AddTetBody(MakeBoxTetMesh(Vec3(0.1, 0.1, 0.1), 1, 1, 1, Vec3(0, 0, 1)), settings);
  settings.name = "bad";
  DeformableBody* bad =
      world.AddTetBody(MakeBoxTetMesh(Vec3(0.1, 0.1, 0.1), 1, 1, 1, Vec3(1, 0, 1)), settings);
  world.stepSimulation(1.0 / 240.0, 1, 1.0 / 240.0);
  const VecX good_x = good->x(), good_v = good->v(), bad_x = bad->x();
  bad->AddNodeForce(0, Vec3(1e300, 0, 0));  // finite, but the node would leave at 1e298 m/s
  try {
    world.stepSimulation(1.0 / 240.0, 1, 1.0 / 240.0);
    FAIL() << "an exploding velocity must fail the step";
  } catch (const SimulationError& e) {
    EXPECT_NE(std::string(e.what()).find("body 'bad'"), std::string::npos) << e.what();
  }
  EXPECT_EQ(good->x(), good_x);  // the healthy body, stepped first, went back too
  EXPECT_EQ(good->v(), good_v);
  EXPECT_EQ(bad->x(), bad_x);
  // And the world steps on afterwards.
  world.stepSimulation(1.0 / 240.0, 1, 1.0 / 240.0);
  EXPECT_LT(good->x().maxCoeff(), good_x.maxCoeff() + 1e-12);
  EXPECT_TRUE(good->x().allFinite());
}

}  // namespace
}  // namespace taut
