// DeformableMultiBodyWorld around Bullet's btMultiBodyDynamicsWorld: without deformables it steps
// bit for bit like stock Bullet; a multibody link resting on a soft pad pushes on it with exactly
// its weight (the link's contact rows carry the load both ways); bad multibodies are named.
#include <gtest/gtest.h>

#include <cstring>

#include "bullet_bridge/multibody_island_body.h"
#include "demos/scenes/gripper_scene.h"
#include "demos/scenes/multibody_world_holder.h"
#include "plugin/box_tet_mesher.h"

namespace taut {
namespace {

constexpr double kDt = 1.0 / 240.0;

// A floating three-link chain (boxes, revolute-prismatic-revolute) dropped from 0.5 m.
btMultiBody* AddFallingChain(btMultiBodyDynamicsWorld& world, MultiBodyObjects& objects) {
  objects.multibodies.push_back(
      std::make_unique<btMultiBody>(3, btScalar(1), btVector3(0.01, 0.01, 0.01), false, true));
  btMultiBody* body = objects.multibodies.back().get();
  const btQuaternion identity = btQuaternion::getIdentity();
  body->setupRevolute(0, 0.5, btVector3(0.002, 0.002, 0.002), -1, identity, btVector3(0, 1, 0),
                      btVector3(0.1, 0, 0), btVector3(0.1, 0, 0), true);
  body->setupPrismatic(1, 0.3, btVector3(0.001, 0.001, 0.001), 0, identity, btVector3(1, 0, 0),
                       btVector3(0.1, 0, 0), btVector3(0.05, 0, 0), true);
  body->setupRevolute(2, 0.2, btVector3(0.001, 0.001, 0.001), 1, identity, btVector3(0, 0, 1),
                      btVector3(0.05, 0, 0), btVector3(0.05, 0, 0), true);
  body->finalizeMultiDof();
  body->setBasePos(btVector3(0.6, 0.1, 0.5));
  body->setWorldToBaseRot(btQuaternion(btVector3(1, 1, 0).normalized(), 0.4));
  body->setJointPos(0, 0.3);
  body->setJointVel(2, 2.0);
  world.addMultiBody(body);
  AddLinkCollider(world, objects, body, -1,
                  std::make_unique<btBoxShape>(btVector3(0.05, 0.05, 0.05)), 0.8);
  for (int l = 0; l < 3; ++l)
    AddLinkCollider(world, objects, body, l,
                    std::make_unique<btBoxShape>(btVector3(0.05, 0.03, 0.03)), 0.8);
  return body;
}

// Ground, the gripper closing and lifting, the falling chain and a falling rigid box.
template <class World>
GripperRig BuildPureMultiBodyScene(MultiBodyWorldHolderOf<World>& holder) {
  AddGroundPlane(holder.world, holder.objects, 1.0);
  GripperSettings gripper;
  gripper.base.z() = 0.6;  // fingers 0.3 m above the ground
  GripperRig rig = AddGripper(holder.world, holder.objects, gripper);
  AddFallingChain(holder.world, holder.objects);
  holder.objects.shapes.push_back(std::make_unique<btBoxShape>(btVector3(0.1, 0.1, 0.1)));
  btVector3 inertia;
  holder.objects.shapes.back()->calculateLocalInertia(1.0, inertia);
  btRigidBody::btRigidBodyConstructionInfo info(1.0, nullptr, holder.objects.shapes.back().get(),
                                                inertia);
  info.m_startWorldTransform.setOrigin(btVector3(-0.5, 0.2, 0.4));
  holder.objects.rigid_bodies.push_back(std::make_unique<btRigidBody>(info));
  holder.world.addRigidBody(holder.objects.rigid_bodies.back().get());
  return rig;
}

// The bits of every multibody's base pose, joint positions and velocities, and every rigid
// body's transform and velocity.
template <class World>
std::vector<btScalar> CollectState(const MultiBodyWorldHolderOf<World>& holder) {
  std::vector<btScalar> state;
  for (const auto& body : holder.objects.multibodies) {
    const btVector3 p = body->getBasePos();
    const btQuaternion r = body->getWorldToBaseRot();
    state.insert(state.end(), {p.x(), p.y(), p.z(), r.x(), r.y(), r.z(), r.w()});
    const btScalar* v = body->getVelocityVector();
    state.insert(state.end(), v, v + 6 + body->getNumDofs());
    for (int l = 0; l < body->getNumLinks(); ++l) state.push_back(body->getJointPos(l));
  }
  for (const auto& rigid : holder.objects.rigid_bodies) {
    const btTransform& t = rigid->getWorldTransform();
    for (int r = 0; r < 3; ++r)
      state.insert(state.end(), {t.getBasis()[r][0], t.getBasis()[r][1], t.getBasis()[r][2]});
    state.insert(state.end(), {t.getOrigin().x(), t.getOrigin().y(), t.getOrigin().z()});
    const btVector3 v = rigid->getLinearVelocity(), w = rigid->getAngularVelocity();
    state.insert(state.end(), {v.x(), v.y(), v.z(), w.x(), w.y(), w.z()});
  }
  return state;
}

TEST(MultiBodyWorld, PureMultiBodySceneRunsBitForBitAsStockBullet) {
  MultiBodyWorldHolderOf<btMultiBodyDynamicsWorld> stock;
  MultiBodyWorldHolderOf<DeformableMultiBodyWorld> taut;
  const GripperRig stock_rig = BuildPureMultiBodyScene(stock);
  const GripperRig taut_rig = BuildPureMultiBodyScene(taut);
  for (int s = 0; s < 480; ++s) {
    const double lift = s < 240 ? 0.0 : 0.1;
    DriveGripper(stock_rig, lift, 50.0, 0.05, 5.0, kDt);
    DriveGripper(taut_rig, lift, 50.0, 0.05, 5.0, kDt);
    stock.world.stepSimulation(kDt, 1, kDt);
    taut.world.stepSimulation(kDt, 1, kDt);
  }
  const std::vector<btScalar> a = CollectState(stock), b = CollectState(taut);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(std::memcmp(a.data(), b.data(), sizeof(btScalar) * a.size()), 0);
  // Not a trivial comparison: the chain fell onto the ground and the gripper moved.
  EXPECT_LT(stock.objects.multibodies[1]->getBasePos().z(), 0.2);
  EXPECT_GT(stock_rig.body->getJointPos(0), 0.05);
  EXPECT_GT(stock_rig.body->getJointPos(1), 0.05);
}

// A 2 kg box (14 cm, 9 pad nodes under it) on a vertical prismatic joint (no motor) resting on
// a soft tet pad whose bottom is fixed: after settling, the contact forces on the pad sum to the
// box's weight.
TEST(MultiBodyWorld, LinkRestingOnSoftPadPushesWithItsWeight) {
  MultiBodyWorldHolderOf<DeformableMultiBodyWorld> holder;
  DeformableBodySettings settings;
  settings.name = "pad";
  settings.material = {50e3, 0.3, 500.0};
  settings.mass_damping = 2.0;
  DeformableBody* pad = holder.world.AddTetBody(
      MakeBoxTetMesh(Vec3(0.3, 0.3, 0.1), 6, 6, 2, Vec3(-0.15, -0.15, 0.0)), settings);
  pad->FixNodesWhere([](const Vec3& p) { return p.z() < 1e-9; });
  const double mass = 2.0;
  holder.objects.multibodies.push_back(
      std::make_unique<btMultiBody>(1, btScalar(1), btVector3(1, 1, 1), true, false));
  btMultiBody* body = holder.objects.multibodies.back().get();
  body->setBasePos(btVector3(0, 0, 0.5));
  body->setupPrismatic(0, mass, btVector3(0.0033, 0.0033, 0.0033), -1, btQuaternion::getIdentity(),
                       btVector3(0, 0, 1), btVector3(0, 0, 0), btVector3(0, 0, 0), true);
  body->finalizeMultiDof();
  body->setJointPos(0, -0.328);  // box bottom 2 mm above the pad
  holder.world.addMultiBody(body);
  const btMultiBodyLinkCollider* box =
      AddLinkCollider(holder.world, holder.objects, body, 0,
                      std::make_unique<btBoxShape>(btVector3(0.07, 0.07, 0.07)), 0.5);
  for (int s = 0; s < 360; ++s) holder.world.stepSimulation(kDt, 1, kDt);
  Vec3 on_pad = Vec3::Zero();
  int contacts = 0;
  for (const DeformableContactPoint& c : holder.world.last_contacts(pad))
    if (c.partner_object == box) {
      on_pad += c.force;
      ++contacts;
    }
  const double weight = mass * 9.81;
  std::printf("[ pad ] %d contacts, force on pad %.5f %.5f %.5f N, weight %.5f N (%.3f %%)\n",
              contacts, on_pad.x(), on_pad.y(), on_pad.z(), weight,
              100.0 * (-on_pad.z() - weight) / weight);
  EXPECT_GT(contacts, 4);
  EXPECT_NEAR(-on_pad.z(), weight, 0.01 * weight);
  // Sideways only static friction (the Kuhn tets' diagonals shear the pad a little; the joint
  // holds the box): within the Coulomb cone, mu = 0.25 (the pad's 0.5 times the box's 0.5).
  EXPECT_LT(std::hypot(on_pad.x(), on_pad.y()), 0.25 * weight);
  EXPECT_LT(std::abs(body->getJointVel(0)), 1e-3);  // at rest on the pad
  EXPECT_GT(body->getJointPos(0), -0.34);           // and not through it
}

TEST(MultiBodyWorld, BadMultiBodiesAreNamed) {
  EXPECT_THROW(MultiBodyIslandBody(nullptr), InputError);
  // 19 prismatic links: 25 generalized velocities, more than a row's 8 blocks hold.
  btMultiBody chain(19, btScalar(1), btVector3(1, 1, 1), true, false);
  for (int l = 0; l < 19; ++l)
    chain.setupPrismatic(l, 1.0, btVector3(1, 1, 1), l - 1, btQuaternion::getIdentity(),
                         btVector3(1, 0, 0), btVector3(0, 0, 0), btVector3(0, 0, 0), true);
  chain.finalizeMultiDof();
  try {
    MultiBodyIslandBody island(&chain);
    ADD_FAILURE() << "a 19-dof multibody was accepted";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("19 joint dofs"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace taut
