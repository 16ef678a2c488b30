// Two-way coupling of deformable and dynamic rigid bodies in one island (docs/architecture.md §4):
// rigid bodies rest on soft ones, impacts conserve momentum, bones drag flesh and flesh drags
// bones, and Bullet's rigid-rigid contacts inside the island hold a stack.
#include <gtest/gtest.h>

#include <cmath>

#include "bullet_bridge/eigen_bullet.h"
#include "bullet_bridge/point_shape_distance.h"
#include "demos/scenes/bullet_world_holder.h"
#include "plugin/box_tet_mesher.h"

namespace taut {
namespace {

constexpr double kStep = 1.0 / 240.0;

// Body settings: E [Pa], density 1000, nu 0.3.
DeformableBodySettings SoftSettings(double youngs_modulus, double damping = 0.0) {
  DeformableBodySettings settings;
  settings.name = "soft";
  settings.material = {youngs_modulus, 0.3, 1000.0};
  settings.mass_damping = damping;
  return settings;
}

// Total linear momentum of the deformables and dynamic rigid bodies [kg m/s].
Vec3 CalcMomentum(const DeformableWorld& world) {
  Vec3 p = Vec3::Zero();
  for (int b = 0; b < world.num_deformable_bodies(); ++b) {
    const DeformableBody& body = world.deformable_body(b);
    for (int i = 0; i < body.num_nodes(); ++i) p += body.mass()[i] * body.v().segment<3>(3 * i);
  }
  for (int i = 0; i < world.getNumCollisionObjects(); ++i) {
    const btRigidBody* rigid = btRigidBody::upcast(world.getCollisionObjectArray()[i]);
    if (rigid != nullptr && rigid->getInvMass() > 0.0)
      p += ToEigen(rigid->getLinearVelocity()) / rigid->getInvMass();
  }
  return p;
}

// Lowest z of the body's nodes.
double MinZ(const DeformableBody& body) {
  double z = HUGE_VAL;
  for (int i = 0; i < body.num_nodes(); ++i) z = std::min(z, body.node_position(i).z());
  return z;
}

// Highest z of the body's nodes.
double MaxZ(const DeformableBody& body) {
  double z = -HUGE_VAL;
  for (int i = 0; i < body.num_nodes(); ++i) z = std::max(z, body.node_position(i).z());
  return z;
}

TEST(RigidCouplingTest, HeavyBoxRestsOnASoftLimitedBlockWithoutSinking) {
  // Soft block 0.4 x 0.4 x 0.2 m (32 kg) limited to 10 % compression, under a rigid box 100x
  // heavier (3.2 t on 0.09 m^2: 350 kPa on a 2 MPa block, 17 % strain without the limit).
  BulletWorldHolder holder;
  holder.AddStaticGround(1.0);
  DeformableBody* block = holder.world.AddTetBody(
      MakeBoxTetMesh(Vec3(0.4, 0.4, 0.2), 4, 4, 1, Vec3(-0.2, -0.2, 0.0)), SoftSettings(2e6, 2.0));
  holder.world.SetStrainLimits(block, StrainLimitSettings::Isotropic(0.9, 1.1));
  const double block_mass = block->mass().sum();
  btRigidBody* box = holder.AddRigidBody(std::make_unique<btBoxShape>(btVector3(0.15, 0.15, 0.05)),
                                         100.0 * block_mass, btVector3(0, 0, 0.25));
  double deepest = 0.0, lowest_box = HUGE_VAL;
#ifdef NDEBUG
  const int steps = 2000;
#else
  const int steps = 1000;  // sanitizer builds (~20x slower): memory checks, a shorter rest
#endif
  for (int i = 0; i < steps; ++i) {
    holder.world.stepSimulation(kStep, 1, kStep);
    // Penetration of the block's nodes into the (possibly tilted) box.
    const double box_bottom = static_cast<double>(box->getWorldTransform().getOrigin().z()) - 0.05;
    for (int n = 0; n < block->num_nodes(); ++n) {
      const PointContact contact = CalcPointShapeDistance(
          block->node_position(n), *box->getCollisionShape(), box->getWorldTransform(), 0.1);
      if (contact.valid) deepest = std::max(deepest, -contact.gap);
    }
    if (i > steps / 2) lowest_box = std::min(lowest_box, box_bottom);
  }
  const double final_bottom = static_cast<double>(box->getWorldTransform().getOrigin().z()) - 0.05;
  const StepStats& stats = holder.world.last_step_stats();
  std::printf(
      "box %.0f kg on %.1f kg block, %d steps: penetration %.2e m, box bottom %.4f m (lowest in "
      "2nd half %.4f), block min z %.2e, islands %d, coupled %d, strain rows %d, violation "
      "%.2e\n",
      100.0 * block_mass, block_mass, steps, deepest, final_bottom, lowest_box, MinZ(*block),
      stats.islands, stats.rigid_bodies_coupled, stats.rows_strain, stats.violation_after);
  EXPECT_EQ(stats.rigid_bodies_coupled, 1);
  EXPECT_GT(final_bottom, 0.2 * 0.9 - 1e-3);    // the 10 % compression limit holds the box up
  EXPECT_LT(final_bottom, 0.2);                 // and the block does carry it (compressed)
  EXPECT_LT(deepest, 1e-3);                     // penetration below 1 mm
  EXPECT_GT(MinZ(*block), -2e-3);               // the block stays on the ground
  EXPECT_NEAR(final_bottom, lowest_box, 2e-3);  // not sinking: the second half is at rest
}

TEST(RigidCouplingTest, BallHittingAFreeSoftBodyConservesLinearMomentum) {
  BulletWorldHolder holder;
  holder.world.setGravity(btVector3(0, 0, 0));
  DeformableBody* block = holder.world.AddTetBody(
      MakeBoxTetMesh(Vec3(0.2, 0.2, 0.2), 2, 2, 2, Vec3(-0.1, -0.1, -0.1)), SoftSettings(1e5));
  btRigidBody* ball =
      holder.AddRigidBody(std::make_unique<btSphereShape>(0.05), 2.0, btVector3(-0.3, 0.02, 0.01));
  ball->setLinearVelocity(btVector3(3.0, 0, 0));
  const Vec3 p0 = CalcMomentum(holder.world);
  double worst = 0.0;
  int contact_steps = 0;
  for (int i = 0; i < 240; ++i) {
    holder.world.stepSimulation(kStep, 1, kStep);
    worst = std::max(worst, (CalcMomentum(holder.world) - p0).norm() / p0.norm());
    if (holder.world.last_step_stats().rows_contact > 0) contact_steps++;
  }
  const double ball_v = static_cast<double>(ball->getLinearVelocity().x());
  std::printf(
      "ball 2 kg at 3 m/s into a %.1f kg block: worst momentum drift %.2e, contact steps "
      "%d, ball vx after %.3f m/s\n",
      block->mass().sum(), worst, contact_steps, ball_v);
  EXPECT_GT(contact_steps, 0);
  EXPECT_LT(ball_v, 2.0);  // the block pushed back
  EXPECT_LT(worst, 0.01);
}

TEST(RigidCouplingTest, DynamicBoneAndAttachedFleshMoveTogetherBothWays) {
  // A free rigid rod inside a soft sleeve, no gravity: pushing the rod drags the sleeve, and the
  // sleeve's inertia slows the rod (momentum is shared, attachment rows hold).
  BulletWorldHolder holder;
  holder.world.setGravity(btVector3(0, 0, 0));
  DeformableBody* sleeve = holder.world.AddTetBody(
      MakeBoxTetMesh(Vec3(0.4, 0.1, 0.1), 4, 1, 1, Vec3(-0.2, -0.05, -0.05)), SoftSettings(5e4));
  btRigidBody* rod = holder.AddRigidBody(std::make_unique<btBoxShape>(btVector3(0.2, 0.01, 0.01)),
                                         1.0, btVector3(0, 0, 0));
  rod->setCollisionFlags(rod->getCollisionFlags() | btCollisionObject::CF_NO_CONTACT_RESPONSE);
  std::vector<int> bone_nodes;
  for (int i = 0; i < sleeve->num_nodes(); ++i)
    if (std::abs(sleeve->node_position(i).x()) > 0.19) bone_nodes.push_back(i);
  holder.world.AttachNodesToRigidBody(sleeve, bone_nodes, rod);
  rod->setLinearVelocity(btVector3(0, 0, 1.0));
  const Vec3 p0 = CalcMomentum(holder.world);
  double worst_gap = 0.0;
  for (int i = 0; i < 120; ++i) {
    holder.world.stepSimulation(kStep, 1, kStep);
    const btTransform t = rod->getWorldTransform();
    for (int node : bone_nodes) {
      const Vec3 rest = sleeve->model().rest_positions().segment<3>(3 * node);
      worst_gap =
          std::max(worst_gap, (sleeve->node_position(node) - ToEigen(t * ToBullet(rest))).norm());
    }
  }
  const double total_mass = 1.0 + sleeve->mass().sum();
  const double rod_vz = static_cast<double>(rod->getLinearVelocity().z());
  std::printf(
      "rod + sleeve: rod vz %.4f m/s (momentum/total mass %.4f), worst anchor gap %.2e m, "
      "joint rows %d\n",
      rod_vz, 1.0 / total_mass, worst_gap, holder.world.last_step_stats().rows_joint);
  EXPECT_EQ(holder.world.last_step_stats().rows_joint, 3 * static_cast<int>(bone_nodes.size()));
  EXPECT_LT(worst_gap, 1e-3);
  EXPECT_LT((CalcMomentum(holder.world) - p0).norm(), 0.01 * p0.norm());
  // The pair moves on together at about the shared velocity p / M (the sleeve oscillates around
  // it): the rod lost most of its 1 m/s to the 4 kg sleeve, and the sleeve's mean velocity
  // matches the rod's.
  const double shared = 1.0 / total_mass;
  double sleeve_vz = 0.0;
  for (int i = 0; i < sleeve->num_nodes(); ++i)
    sleeve_vz += sleeve->mass()[i] * sleeve->v()[3 * i + 2];
  sleeve_vz /= sleeve->mass().sum();
  EXPECT_NEAR(rod_vz, shared, 0.5 * shared);
  EXPECT_NEAR(sleeve_vz, shared, 0.5 * shared);
}

TEST(RigidCouplingTest, RigidStackOnASoftBodyHoldsThroughTheIslandsRigidContacts) {
  BulletWorldHolder holder;
  holder.AddStaticGround(1.0);
  DeformableBody* pad = holder.world.AddTetBody(
      MakeBoxTetMesh(Vec3(0.4, 0.4, 0.1), 4, 4, 1, Vec3(-0.2, -0.2, 0.0)), SoftSettings(5e5, 2.0));
  std::vector<btRigidBody*> boxes;
  for (int k = 0; k < 3; ++k)
    boxes.push_back(holder.AddRigidBody(std::make_unique<btBoxShape>(btVector3(0.1, 0.1, 0.05)),
                                        1.0, btVector3(0, 0, 0.15 + 0.1 * k), 0.8));
  int rigid_rows = 0;
  for (int i = 0; i < 480; ++i) {
    holder.world.stepSimulation(kStep, 1, kStep);
    rigid_rows = std::max(rigid_rows, holder.world.last_step_stats().rows_rigid_contact);
  }
  const StepStats& stats = holder.world.last_step_stats();
  std::printf(
      "stack of 3 on a pad: box z %.4f %.4f %.4f, pad top %.4f, coupled %d, rigid rows "
      "%d\n",
      static_cast<double>(boxes[0]->getWorldTransform().getOrigin().z()),
      static_cast<double>(boxes[1]->getWorldTransform().getOrigin().z()),
      static_cast<double>(boxes[2]->getWorldTransform().getOrigin().z()), MaxZ(*pad),
      stats.rigid_bodies_coupled, rigid_rows);
  EXPECT_EQ(stats.rigid_bodies_coupled, 3);
  EXPECT_GT(rigid_rows, 0);
  for (int k = 0; k < 3; ++k) {
    const btVector3 p = boxes[k]->getWorldTransform().getOrigin();
    EXPECT_NEAR(static_cast<double>(p.x()), 0.0, 0.01) << "box " << k;
    EXPECT_NEAR(static_cast<double>(p.y()), 0.0, 0.01) << "box " << k;
    // Stacked: each box 0.1 m above the one below (Bullet's contact tolerance ~ 1 cm).
    if (k > 0)
      EXPECT_NEAR(static_cast<double>(p.z() - boxes[k - 1]->getWorldTransform().getOrigin().z()),
                  0.1, 0.01);
    EXPECT_LT(boxes[k]->getLinearVelocity().length(), 0.05) << "box " << k << " at rest";
  }
  EXPECT_GT(static_cast<double>(boxes[0]->getWorldTransform().getOrigin().z()) - 0.05,
            MaxZ(*pad) - 0.01);  // the bottom box sits on the pad, not in it
}

// Highest bounce of a ball dropped from 0.5 m onto a heavy rigid slab lying on a soft pad, with
// the given restitution (ball and slab; Bullet combines them by the product).
double CalcBounceOnSlab(double restitution) {
  BulletWorldHolder holder;
  holder.AddStaticGround(1.0);
  holder.world.AddTetBody(MakeBoxTetMesh(Vec3(0.4, 0.4, 0.1), 4, 4, 1, Vec3(-0.2, -0.2, 0.0)),
                          SoftSettings(1e6, 5.0));
  btRigidBody* slab = holder.AddRigidBody(std::make_unique<btBoxShape>(btVector3(0.15, 0.15, 0.02)),
                                          50.0, btVector3(0, 0, 0.121), 0.5, 1.0);
  btRigidBody* ball = holder.AddRigidBody(std::make_unique<btSphereShape>(0.03), 0.1,
                                          btVector3(0, 0, 0.141 + 0.5 + 0.03), 0.5, restitution);
  bool hit = false;
  double bounce = 0.0;
  for (int i = 0; i < 360; ++i) {
    holder.world.stepSimulation(kStep, 1, kStep);
    const double bottom = static_cast<double>(ball->getWorldTransform().getOrigin().z()) - 0.03;
    const double slab_top = static_cast<double>(slab->getWorldTransform().getOrigin().z()) + 0.02;
    if (bottom - slab_top < 0.01) hit = true;
    if (hit) bounce = std::max(bounce, bottom - slab_top);
    if (hit && holder.world.last_step_stats().rows_rigid_contact > 0)
      EXPECT_EQ(holder.world.last_step_stats().rigid_bodies_coupled, 2) << "step " << i;
  }
  return bounce;
}

TEST(RigidCouplingTest, RestitutionOfRigidContactsInsideTheIslandIsHonoured) {
  const double elastic = CalcBounceOnSlab(0.9), inelastic = CalcBounceOnSlab(0.0);
  std::printf(
      "ball on a slab on a soft pad, dropped 0.5 m: bounce %.4f m (e = 0.9, ideal %.4f), "
      "%.4f m (e = 0)\n",
      elastic, 0.81 * 0.5, inelastic);
  EXPECT_NEAR(elastic, 0.81 * 0.5, 0.05 * 0.81 * 0.5);  // e^2 h: the 50 kg slab barely moves
  EXPECT_LT(inelastic, 0.01);
}

}  // namespace
}  // namespace taut
