// The haptic loop (bullet_bridge/haptic_force_loop.h) on paper A's finger held pressed on the
// table: the frozen LCP must give the step's own force with no motion, follow a re-step for small
// motions, keep friction in the cone and leave the world untouched.
#include "bullet_bridge/haptic_force_loop.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "bullet_bridge/eigen_bullet.h"
#include "constraints/deformable_island_body.h"
#include "constraints/node_height_source.h"
#include "demos/scenes/bullet_world_holder.h"
#include "demos/scenes/finger_scene.h"
#include "plugin/box_tet_mesher.h"
#include "tests/allocation_counter.h"

namespace taut {
namespace {

constexpr double kDt = 1e-3;  // step [s]

// The flat anisotropic press held at its stop (contact and strain-limit rows active); a table of
// friction `table_friction` (times the finger's 0.5).
std::unique_ptr<FingerScene> MakeHeldFinger(double table_friction = 0.0) {
  FingerSceneSettings settings;
  settings.target_force = 20.0;
  settings.hold_time = 1.0;
  auto scene = std::make_unique<FingerScene>(
      std::vector<FingerPress>{{FingerPressAxis::kFlat, FingerScene::Anisotropic()}}, settings);
  scene->table()->setFriction(table_friction);
  for (int step = 0; step < 2000 && scene->result(0).stop_reason.empty(); ++step) scene->Step(kDt);
  EXPECT_EQ(scene->result(0).stop_reason, "force");
  for (int step = 0; step < 5; ++step) scene->Step(kDt);
  return scene;
}

// The last substep's wrench on `object` from the contact report (zero when none).
RigidBodyWrench FindReportedWrench(const DeformableWorld& world, const btCollisionObject* object) {
  for (const RigidBodyWrench& wrench : world.last_rigid_wrenches())
    if (wrench.object == object) return wrench;
  return RigidBodyWrench();
}

// Moves a static or kinematic body to `pose` (and its motion state, which Bullet reads for
// kinematic bodies at the next step).
void PlaceBody(DeformableWorld& world, btRigidBody* body, const btTransform& pose) {
  body->setWorldTransform(pose);
  if (body->getMotionState() != nullptr) body->getMotionState()->setWorldTransform(pose);
  world.updateSingleAabb(body);
}

btTransform Shifted(const btTransform& pose, const Vec3& d) {
  btTransform shifted = pose;
  shifted.setOrigin(pose.getOrigin() + ToBullet(d));
  return shifted;
}

// A step redone from `before` with `body` at `moved` instead of `pose_after` (its pose at the end
// of that step); the other bodies as they were. Returns the reported wrench on `probe`; the world
// is back at `before` afterwards.
RigidBodyWrench Restep(FingerScene& scene, const WorldSnapshot& before, btRigidBody* body,
                       const btTransform& pose_after, const btTransform& moved,
                       const btRigidBody* probe) {
  DeformableWorld& world = scene.world();
  const btTransform bone_pose = scene.bone()->getWorldTransform();
  world.RestoreSnapshot(before);
  PlaceBody(world, scene.bone(), bone_pose);  // the step's bone target
  PlaceBody(world, body, moved);
  world.stepSimulation(kDt, 1, kDt);
  const RigidBodyWrench wrench = FindReportedWrench(world, probe);
  PlaceBody(world, body, pose_after);
  world.RestoreSnapshot(before);
  return wrench;
}

// (a) With no motion since the step, the loop re-solves the step's own LCP: the table's wrench
// equals the contact report's (force and torque) to the PGS tolerance, in a few sweeps.
TEST(HapticForceLoopTest, NoMotionGivesTheStepsWrench) {
  std::unique_ptr<FingerScene> scene = MakeHeldFinger();
  DeformableWorld& world = scene->world();
  const RigidBodyWrench reported = FindReportedWrench(world, scene->table());
  ASSERT_GT(reported.force.norm(), 10.0);
  HapticForceLoop loop = HapticForceLoop::Capture(world, scene->table());
  EXPECT_EQ(loop.num_islands(), 1);
  EXPECT_GT(loop.num_tool_rows(), 0);
  const HapticWrench wrench = loop.CalcToolWrench(ToolMotion());
  std::printf(
      "table: report %.6f N, loop %.6f N, |difference| %.1e N, torque %.1e N m (%d rows, "
      "%d tool rows, %d sweeps, %.1f us)\n",
      reported.force.z(), wrench.force.z(), (wrench.force - reported.force).norm(),
      (wrench.torque - reported.torque).norm(), loop.lcp().size(), loop.num_tool_rows(),
      wrench.sweeps, wrench.microseconds);
  EXPECT_TRUE(wrench.converged);
  // The step's own multipliers solve the frozen LCP to its PGS tolerance (measured: 1.3e-7 N of
  // 20.1 N, 2.6e-9 N m).
  EXPECT_LT((wrench.force - reported.force).norm(), 1e-5 * reported.force.norm());
  EXPECT_LT((wrench.torque - reported.torque).norm(), 1e-6);
  // The same pose as a transform.
  const HapticWrench same = loop.CalcToolWrench(scene->table()->getWorldTransform());
  EXPECT_LT((same.force - reported.force).norm(), 1e-5 * reported.force.norm());
}

// (b) Pushing the table further into the finger raises the force monotonically, and for a small
// push the change matches the step redone with the table moved (same start state).
TEST(HapticForceLoopTest, PushingTheTableInFollowsARestep) {
  std::unique_ptr<FingerScene> scene = MakeHeldFinger();
  DeformableWorld& world = scene->world();
  btRigidBody* table = scene->table();
  const WorldSnapshot before = world.SaveSnapshot();
  scene->Simulate(kDt);  // the step the loop freezes
  const btTransform pose = table->getWorldTransform();
  HapticForceLoop loop = HapticForceLoop::Capture(world, table);
  const double F0 = loop.CalcToolWrench(ToolMotion()).force.z();
  const double R0 = Restep(*scene, before, table, pose, pose, table).force.z();
  EXPECT_NEAR(F0, R0, 1e-3 * std::abs(R0));
  double last = F0;
  for (double d : {0.25e-6, 0.5e-6, 1e-6, 2e-6}) {
    ToolMotion motion;
    motion.displacement = Vec3(0.0, 0.0, d);
    const HapticWrench w = loop.CalcToolWrench(motion);
    const double R =
        Restep(*scene, before, table, pose, Shifted(pose, motion.displacement), table).force.z();
    std::printf("table up %.2f um: loop %.4f N (%d sweeps, %.1f us), restep %.4f N\n", 1e6 * d,
                w.force.z(), w.sweeps, w.microseconds, R);
    EXPECT_LT(w.force.z(), last);  // the table's force points down: it grows more negative
    last = w.force.z();
    EXPECT_NEAR(w.force.z() - F0, R - R0, 0.05 * std::abs(R - R0)) << d;
  }
}

// (b) The bone driven further down: the force the rows put on it grows, and its change matches the
// change of the table's force in the step redone with the bone moved (the flesh passes the
// contact force on; inertia and the free nodes' own motion take the rest).
TEST(HapticForceLoopTest, PushingTheBoneInFollowsARestep) {
  std::unique_ptr<FingerScene> scene = MakeHeldFinger();
  DeformableWorld& world = scene->world();
  btRigidBody* bone = scene->bone();
  const WorldSnapshot before = world.SaveSnapshot();
  scene->Simulate(kDt);
  const btTransform pose = bone->getWorldTransform();
  const double table0 = FindReportedWrench(world, scene->table()).force.z();
  HapticForceLoop loop = HapticForceLoop::Capture(world, bone);
  const double F0 = loop.CalcToolWrench(ToolMotion()).force.z();
  std::printf("bone: loop %.4f N, table %.4f N (%d rows, %d tool rows)\n", F0, table0,
              loop.lcp().size(), loop.num_tool_rows());
  EXPECT_NEAR(F0, -table0, 0.1 * std::abs(table0));
  double last = F0;
  for (double d : {0.25e-6, 0.5e-6, 1e-6, 2e-6}) {
    ToolMotion motion;
    motion.displacement = Vec3(0.0, 0.0, -d);
    const HapticWrench w = loop.CalcToolWrench(motion);
    const double R =
        Restep(*scene, before, bone, pose, Shifted(pose, motion.displacement), scene->table())
            .force.z();
    std::printf("bone down %.2f um: loop %.4f N (%d sweeps, %.1f us), restep table %.4f N\n",
                1e6 * d, w.force.z(), w.sweeps, w.microseconds, R);
    EXPECT_GT(w.force.z(), last);
    last = w.force.z();
    EXPECT_NEAR(w.force.z() - F0, -(R - table0), 0.05 * std::abs(R - table0)) << d;
  }
}

// (b) Tilting the table about its centre of mass (given as the table's new transform): the torque
// change about that point follows the step redone with the table tilted.
TEST(HapticForceLoopTest, TiltingTheTableFollowsARestepInTorque) {
  std::unique_ptr<FingerScene> scene = MakeHeldFinger();
  DeformableWorld& world = scene->world();
  btRigidBody* table = scene->table();
  const WorldSnapshot before = world.SaveSnapshot();
  scene->Simulate(kDt);
  const btTransform pose = table->getWorldTransform();
  HapticForceLoop loop = HapticForceLoop::Capture(world, table);
  const RigidBodyWrench R0 = Restep(*scene, before, table, pose, pose, table);
  const Vec3 T0 = loop.CalcToolWrench(pose).torque;
  EXPECT_LT((T0 - R0.torque).norm(), 1e-3 * R0.torque.norm());
  for (double angle : {2e-5, 5e-5, 1e-4}) {
    // A turn about +y through the centre of mass lifts the table's -x side, under the finger's
    // tip end (the finger lies along +x from the origin, the table's centre at x = 0.035 m).
    btTransform tilted = pose;
    tilted.setBasis(btMatrix3x3(btQuaternion(btVector3(0, 1, 0), angle)) * pose.getBasis());
    const HapticWrench w = loop.CalcToolWrench(tilted);
    const RigidBodyWrench R = Restep(*scene, before, table, pose, tilted, table);
    std::printf(
        "tilt %.0e rad: torque y change loop %.6f N m, restep %.6f N m; force z change "
        "loop %.4f N, restep %.4f N\n",
        angle, w.torque.y() - T0.y(), R.torque.y() - R0.torque.y(), w.force.z() - R0.force.z(),
        R.force.z() - R0.force.z());
    EXPECT_NEAR(w.torque.y() - T0.y(), R.torque.y() - R0.torque.y(),
                0.05 * std::abs(R.torque.y() - R0.torque.y()))
        << angle;
    EXPECT_NEAR(w.force.z() - R0.force.z(), R.force.z() - R0.force.z(),
                0.05 * std::abs(R.force.z() - R0.force.z()) + 1e-4)
        << angle;
  }
}

// (c) With friction (mu = 0.5), sliding the table under the finger: every contact's friction
// stays on its Coulomb disk, the total stays in the cone, and a long slide saturates it.
TEST(HapticForceLoopTest, FrictionStaysInTheCone) {
  std::unique_ptr<FingerScene> scene = MakeHeldFinger(1.0);
  HapticForceLoop loop = HapticForceLoop::Capture(scene->world(), scene->table());
  const FrozenIslandLcp& lcp = loop.lcp();
  double mu = 0.0;
  for (double slide : {1e-6, 1e-5, 1e-4, 1e-3, 1e-2}) {
    ToolMotion motion;
    motion.displacement = Vec3(slide, 0.0, 0.0);
    const HapticWrench w = loop.CalcToolWrench(motion);
    int pairs = 0;
    for (int c = 0; c < lcp.size(); ++c) {
      const PgsRow& row = lcp.rows()[c];
      if (row.kind != RowKind::kFriction || row.partner < c) continue;
      ++pairs;
      mu = row.mu;
      const double t = std::hypot(lcp.lambda()[c], lcp.lambda()[row.partner]);
      EXPECT_LE(t, row.mu * lcp.lambda()[row.normal] * (1.0 + 1e-9) + 1e-15) << c;
    }
    ASSERT_GT(pairs, 0);
    const double tangential = std::hypot(w.force.x(), w.force.y());
    std::printf("slide %.0e m: tangential %.4f N of mu |F_n| = %.4f N\n", slide, tangential,
                mu * std::abs(w.force.z()));
    EXPECT_LE(tangential, mu * std::abs(w.force.z()) * (1.0 + 1e-9));
    if (slide >= 1e-2) EXPECT_GT(tangential, 0.95 * mu * std::abs(w.force.z()));
  }
}

// (d) Capture and queries read the world and write nothing: the state hash is unchanged, and the
// world steps on bit-identically to a twin that was never queried (positions, velocities and,
// through the next solves, warm starts).
TEST(HapticForceLoopTest, QueriesLeaveTheWorldBitIdentical) {
  std::unique_ptr<FingerScene> queried = MakeHeldFinger(1.0);
  std::unique_ptr<FingerScene> twin = MakeHeldFinger(1.0);
  ASSERT_EQ(queried->CalcStateHash(), twin->CalcStateHash());
  const std::uint64_t hash = queried->CalcStateHash();
  for (const btRigidBody* tool : {queried->bone(), queried->table()}) {
    HapticForceLoop loop = HapticForceLoop::Capture(queried->world(), tool);
    for (int k = 0; k < 50; ++k) {
      ToolMotion motion;
      motion.displacement = Vec3(1e-6 * std::sin(k), 0.0, -2e-6 * std::cos(0.3 * k));
      motion.rotation = Vec3(1e-4 * std::sin(0.7 * k), 0.0, 0.0);
      loop.CalcToolWrench(motion);
    }
  }
  EXPECT_EQ(queried->CalcStateHash(), hash);
  for (int step = 0; step < 5; ++step) {
    queried->Step(kDt);
    twin->Step(kDt);
    ASSERT_EQ(queried->CalcStateHash(), twin->CalcStateHash()) << step;
    const Vec3 a = FindReportedWrench(queried->world(), queried->table()).force;
    const Vec3 b = FindReportedWrench(twin->world(), twin->table()).force;
    EXPECT_EQ(a, b) << step;
  }
}

// A query allocates nothing (a haptic thread must not wait on the heap).
TEST(HapticForceLoopTest, QueriesAllocateNothing) {
  std::unique_ptr<FingerScene> scene = MakeHeldFinger(1.0);
  HapticForceLoop loop = HapticForceLoop::Capture(scene->world(), scene->bone());
  const btTransform pose = scene->bone()->getWorldTransform();
  loop.CalcToolWrench(ToolMotion());
  testing::ScopedAllocationCounter counter;
  for (int k = 0; k < 20; ++k) {
    ToolMotion motion;
    motion.displacement = Vec3(1e-6 * k, 0.0, -1e-7 * k);
    loop.CalcToolWrench(motion);
    btTransform moved = pose;
    moved.setOrigin(pose.getOrigin() + btVector3(0, 0, -1e-7 * k));
    loop.CalcToolWrench(moved);
  }
  EXPECT_EQ(counter.count(), 0u);
}

// A loop is a standalone value: queried on another thread while the world steps on, it answers
// exactly what a copy answers with the world idle.
TEST(HapticForceLoopTest, LoopAnswersTheSameWhileTheWorldSteps) {
  std::unique_ptr<FingerScene> scene = MakeHeldFinger(1.0);
  HapticForceLoop loop = HapticForceLoop::Capture(scene->world(), scene->bone());
  HapticForceLoop copy = loop;
  auto query = [](HapticForceLoop& l, std::vector<Vec3>& forces) {
    for (int k = 0; k < 200; ++k) {
      ToolMotion motion;
      motion.displacement = Vec3(2e-6 * std::sin(0.1 * k), 0.0, -1e-6 * (1.0 - std::cos(0.05 * k)));
      forces.push_back(l.CalcToolWrench(motion).force);
    }
  };
  std::vector<Vec3> during, idle;
  std::thread haptic([&] { query(loop, during); });
  for (int step = 0; step < 10; ++step) scene->Step(kDt);
  haptic.join();
  query(copy, idle);
  ASSERT_EQ(during.size(), idle.size());
  for (size_t k = 0; k < idle.size(); ++k) EXPECT_EQ(during[k], idle[k]) << k;
}

// Bad tools: a dynamic rigid body, or one not in the world.
TEST(HapticForceLoopTest, BadToolsThrow) {
  std::unique_ptr<FingerScene> scene = MakeHeldFinger();
  btSphereShape shape(0.01);
  btRigidBody outside(1.0, nullptr, &shape, btVector3(1e-4, 1e-4, 1e-4));
  EXPECT_THROW(HapticForceLoop::Capture(scene->world(), &outside), InputError);
  EXPECT_THROW(HapticForceLoop::Capture(scene->world(), nullptr), InputError);
  // In the world but touching nothing: no rows, no force.
  outside.setWorldTransform(btTransform(btQuaternion::getIdentity(), btVector3(0, 0, 1)));
  scene->world().addRigidBody(&outside);
  HapticForceLoop loop = HapticForceLoop::Capture(scene->world(), &outside);
  EXPECT_EQ(loop.lcp().size(), 0);
  ToolMotion motion;
  motion.displacement = Vec3(0.0, 0.0, -1e-3);
  EXPECT_EQ(loop.CalcToolWrench(motion).force, Vec3::Zero());
  scene->world().removeRigidBody(&outside);
}

// A dynamic tool: a 0.2 kg rigid box resting on a soft block on the ground, in the block's
// island. Its velocity becomes the user's (it leaves W): with no motion the loop gives the box's
// reported wrench, and pressing it down raises the force monotonically.
TEST(HapticForceLoopTest, DynamicToolInTheIsland) {
  BulletWorldHolder holder;
  holder.AddStaticGround(1.0);
  DeformableBodySettings settings;
  settings.name = "soft block";
  settings.material = {2e5, 0.3, 1000.0};
  settings.mass_damping = 5.0;
  holder.world.AddTetBody(MakeBoxTetMesh(Vec3(0.1, 0.1, 0.04), 4, 4, 2), settings);
  btRigidBody* box = holder.AddRigidBody(std::make_unique<btBoxShape>(btVector3(0.02, 0.02, 0.01)),
                                         0.2, btVector3(0.05, 0.05, 0.0505), 0.5);
  for (int step = 0; step < 300; ++step) holder.world.stepSimulation(kDt, 1, kDt);
  const RigidBodyWrench reported = FindReportedWrench(holder.world, box);
  ASSERT_GT(reported.force.z(), 1.0);  // carries the box's weight, about 1.96 N
  HapticForceLoop loop = HapticForceLoop::Capture(holder.world, box);
  ASSERT_EQ(loop.num_islands(), 1);
  const HapticWrench w0 = loop.CalcToolWrench(ToolMotion());
  std::printf("dynamic box: report %.6f N, loop %.6f N (%d rows, %d tool rows, %d sweeps)\n",
              reported.force.z(), w0.force.z(), loop.lcp().size(), loop.num_tool_rows(), w0.sweeps);
  // This island (102 rows on 225 free DOFs) takes the primal path by its rows per DOF, and the
  // dual path for a while after a primal failure the dual retry certified. Either path's
  // multipliers solve the frozen LCP to the certificate's tolerance, the loop's PGS to its own.
  // The certificate lets a pushing contact row stand open by up to its complementarity (1e-3 in
  // C units, 1e-5 m), which the frozen LCP closes: at the contact stiffness the loop measures
  // (the 4 um press below, about 15 N/mm) that is up to 0.15 N. Measured: 3e-6 of the force
  // after a dual step, 0.107 N after four primal steps certified at their warm start
  // (complementarity 7.5e-4).
  const SqpSettings& solver = holder.world.solver_settings();
  const double open_gap = holder.world.last_step_stats().kkt_complementarity *
                          solver.contact_tolerance / solver.violation_tolerance;
  ToolMotion press;
  press.displacement = Vec3(0.0, 0.0, -4e-6);
  const double stiffness = (loop.CalcToolWrench(press).force.z() - w0.force.z()) / 4e-6;
  const double force_bound = 5e-3 * reported.force.norm() + stiffness * open_gap;
  std::printf("open gap %.2e m at %.0f N/m: force bound %.4f N\n", open_gap, stiffness,
              force_bound);
  EXPECT_LT((w0.force - reported.force).norm(), force_bound);
  EXPECT_LT((w0.torque - reported.torque).norm(), 0.02 * force_bound);  // 0.02 m: the box's size
  double last = w0.force.z();
  for (double d : {0.5e-6, 1e-6, 2e-6, 4e-6}) {
    ToolMotion motion;
    motion.displacement = Vec3(0.0, 0.0, -d);
    const HapticWrench w = loop.CalcToolWrench(motion);
    std::printf("box down %.1f um: %.4f N (%d sweeps)\n", 1e6 * d, w.force.z(), w.sweeps);
    EXPECT_GT(w.force.z(), last);
    last = w.force.z();
  }
}

// An island whose body holds no factor of this step's A (here: a body never stepped, as after an
// unconstrained solve that reused an older factor by PCG with no solve of A since) is refused
// with an InputError naming the body, rather than factored behind the world's back.
TEST(HapticForceLoopTest, IslandWithoutThisStepsFactorIsRefused) {
  BulletWorldHolder holder;
  DeformableBodySettings settings;
  settings.name = "unfactored block";
  settings.material = {1e5, 0.3, 1000.0};
  DeformableBody* body =
      holder.world.AddTetBody(MakeBoxTetMesh(Vec3(0.1, 0.1, 0.05), 2, 2, 1), settings);
  ASSERT_FALSE(body->system().factor_is_current());
  DeformableIslandBody island_body(*body);
  const std::vector<IslandBody*> bodies = {&island_body};
  NodeHeightSource floor(*body, 0.01, 1e-3, 0);  // the bottom nodes below z_min: active rows
  const std::vector<ConstraintSource*> sources = {&floor};
  IslandRows rows;
  rows.Collect(kDt, bodies, sources, {body->v()}, 1.0);
  ASSERT_FALSE(rows.empty());
  try {
    FreezeIsland(kDt, bodies, rows, VecX::Zero(rows.size()));
    ADD_FAILURE() << "FreezeIsland solved with a factor that is not this step's";
  } catch (const InputError& e) {
    std::printf("refused: %s\n", e.what());
    EXPECT_NE(std::string(e.what()).find("unfactored block"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(body->system().factor_is_current());  // nothing was factored
}

}  // namespace
}  // namespace taut
