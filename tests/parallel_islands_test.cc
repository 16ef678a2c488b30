// DeformableWorld::SetThreadCount: scenes of several islands stepped with 1 and with 2 threads end
// in bitwise identical deformable and rigid states and step statistics, and the pool under it
// runs every task once and rethrows the failure of the lowest task.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "bullet_bridge/island_thread_pool.h"
#include "demos/scenes/bullet_world_holder.h"
#include "demos/scenes/tet_beam_scene.h"
#include "plugin/box_tet_mesher.h"

namespace taut {
namespace {

// Pinned-hash (Release) builds step longer; sanitizer builds are ~10x slower.
constexpr int kParallelSteps = TAUT_PINNED_HASHES ? 20 : 4;
constexpr int kParallelSceneSteps = TAUT_PINNED_HASHES ? 10 : 2;
// The limited beams need this many steps of 1/240 s before their limits act, in every build.
constexpr int kLimitedBeamSteps = 20;

// Four strain-limited cantilevers side by side (the tet_beam scene's two limited materials, two
// beams each): four islands with rows, none touching another.
std::unique_ptr<TetBeamScene> MakeFourLimitedBeams() {
  const std::vector<TetBeamScene::Beam> defaults = TetBeamScene::DefaultBeams();
  return std::make_unique<TetBeamScene>(
      std::vector<TetBeamScene::Beam>{defaults[2], defaults[3], defaults[3], defaults[2]}, 6, 2);
}

// Two energy-limited soft blocks on one static ground, each with a dynamic box on top: two
// islands (block + box) that share the ground as a partner.
struct BlocksOnGround {
  BulletWorldHolder holder;
  BlocksOnGround() {
    holder.world.setGravity(btVector3(0, 0, -9.81));
    holder.AddStaticGround(0.8);
    for (int b = 0; b < 2; ++b) {
      DeformableBodySettings settings;
      settings.name = "block" + std::to_string(b);
      settings.material = {2e4, 0.3, 1000};
      const Vec3 corner(1.0 * b, 0.0, 0.001);
      DeformableBody* block =
          holder.world.AddTetBody(MakeBoxTetMesh(Vec3(0.3, 0.3, 0.2), 3, 3, 2, corner), settings);
      holder.world.SetEnergyLimits(block, EnergyLimitSettings::EnergyDensity(20.0));
      holder.AddRigidBody(std::make_unique<btBoxShape>(btVector3(0.08, 0.08, 0.04)), 2.0,
                          btVector3(1.0 * b + 0.15, 0.15, 0.245));
    }
  }
  DeformableWorld& world() { return holder.world; }
};

// Bitwise equality of two doubles (also for NaN and -0).
bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

// Every deformable x and v and every rigid transform and velocity of `a` and `b` are bitwise
// equal.
void ExpectSameWorldState(const DeformableWorld& a, const DeformableWorld& b) {
  ASSERT_EQ(a.num_deformable_bodies(), b.num_deformable_bodies());
  for (int d = 0; d < a.num_deformable_bodies(); ++d) {
    const DeformableBody& p = a.deformable_body(d);
    const DeformableBody& q = b.deformable_body(d);
    ASSERT_EQ(p.x().size(), q.x().size());
    EXPECT_EQ(0, std::memcmp(p.x().data(), q.x().data(), sizeof(double) * p.x().size()))
        << "x of body " << d;
    EXPECT_EQ(0, std::memcmp(p.v().data(), q.v().data(), sizeof(double) * p.v().size()))
        << "v of body " << d;
  }
  const btCollisionObjectArray& objects_a = a.getCollisionObjectArray();
  const btCollisionObjectArray& objects_b = b.getCollisionObjectArray();
  ASSERT_EQ(objects_a.size(), objects_b.size());
  for (int i = 0; i < objects_a.size(); ++i) {
    const btRigidBody* p = btRigidBody::upcast(objects_a[i]);
    const btRigidBody* q = btRigidBody::upcast(objects_b[i]);
    if (p == nullptr || q == nullptr) continue;
    for (int k = 0; k < 3; ++k) {
      EXPECT_TRUE(
          SameBits(p->getWorldTransform().getOrigin()[k], q->getWorldTransform().getOrigin()[k]))
          << "origin of object " << i;
      EXPECT_TRUE(SameBits(p->getLinearVelocity()[k], q->getLinearVelocity()[k]))
          << "velocity of object " << i;
      EXPECT_TRUE(SameBits(p->getAngularVelocity()[k], q->getAngularVelocity()[k]))
          << "angular velocity of object " << i;
      for (int r = 0; r < 3; ++r)
        EXPECT_TRUE(SameBits(p->getWorldTransform().getBasis()[r][k],
                             q->getWorldTransform().getBasis()[r][k]))
            << "rotation of object " << i;
    }
  }
}

// Every count, violation and residual of two step statistics is bitwise equal (times differ).
void ExpectSameStepCounts(const StepStats& a, const StepStats& b) {
  EXPECT_EQ(a.rows_strain, b.rows_strain);
  EXPECT_EQ(a.rows_energy, b.rows_energy);
  EXPECT_EQ(a.rows_contact, b.rows_contact);
  EXPECT_EQ(a.rows_rigid_contact, b.rows_rigid_contact);
  EXPECT_EQ(a.rows_joint, b.rows_joint);
  EXPECT_EQ(a.pgs_sweeps, b.pgs_sweeps);
  EXPECT_EQ(a.active_set_solves, b.active_set_solves);
  EXPECT_EQ(a.sqp_iterations, b.sqp_iterations);
  EXPECT_EQ(a.restoration_iterations, b.restoration_iterations);
  EXPECT_EQ(a.islands_dual, b.islands_dual);
  EXPECT_EQ(a.islands_primal, b.islands_primal);
  EXPECT_EQ(a.newton_iterations, b.newton_iterations);
  EXPECT_EQ(a.pcg_iterations, b.pcg_iterations);
  EXPECT_EQ(a.newton_factorizations, b.newton_factorizations);
  EXPECT_EQ(a.islands, b.islands);
  EXPECT_EQ(a.rigid_bodies_coupled, b.rigid_bodies_coupled);
  EXPECT_EQ(a.substeps, b.substeps);
  EXPECT_EQ(a.converged, b.converged);
  EXPECT_TRUE(SameBits(a.violation_before, b.violation_before));
  EXPECT_TRUE(SameBits(a.violation_after, b.violation_after));
  EXPECT_TRUE(SameBits(a.stationarity, b.stationarity));
  EXPECT_TRUE(SameBits(a.lcp_residual, b.lcp_residual));
  EXPECT_TRUE(SameBits(a.kkt_primal, b.kkt_primal));
  EXPECT_TRUE(SameBits(a.kkt_complementarity, b.kkt_complementarity));
  EXPECT_TRUE(SameBits(a.kkt_dual, b.kkt_dual));
  for (int i = 0; i < kNumRowTypes; ++i) {
    EXPECT_TRUE(SameBits(a.kkt_primal_by_type[i], b.kkt_primal_by_type[i])) << i;
    EXPECT_TRUE(SameBits(a.kkt_complementarity_by_type[i], b.kkt_complementarity_by_type[i])) << i;
  }
}

// The most rows of each kind that one step of a run emitted.
struct PeakRows {
  int strain = 0;
  int contact = 0;
};

// Steps `one` on 1 thread and `two` on 2 side by side, checking every step's statistics and at
// least `min_islands` solved islands per step, for `steps` steps, then the final states; returns
// the peak row counts.
PeakRows ExpectOneAndTwoThreadsAgree(DeformableWorld& one, DeformableWorld& two, double dt,
                                     int steps, int min_islands) {
  one.SetThreadCount(1);
  two.SetThreadCount(2);
  PeakRows peak;
  EXPECT_EQ(two.thread_count(), 2);
  for (int step = 0; step < steps; ++step) {
    one.stepSimulation(dt, 1, dt);
    two.stepSimulation(dt, 1, dt);
    SCOPED_TRACE("step " + std::to_string(step));
    EXPECT_GE(two.last_step_stats().islands, min_islands) << "the scene lost its islands";
    ExpectSameStepCounts(one.last_step_stats(), two.last_step_stats());
    peak.strain = std::max(peak.strain, two.last_step_stats().rows_strain);
    peak.contact = std::max(peak.contact, two.last_step_stats().rows_contact);
  }
  ExpectSameWorldState(one, two);
  return peak;
}

TEST(ParallelIslandsTest, FourLimitedBeamsGiveTheSameStateOnOneAndTwoThreads) {
  auto one = MakeFourLimitedBeams();
  auto two = MakeFourLimitedBeams();
  const PeakRows peak =
      ExpectOneAndTwoThreadsAgree(one->world(), two->world(), 1.0 / 240.0, kLimitedBeamSteps, 4);
  EXPECT_GT(peak.strain, 0) << "the limits never acted";
}

TEST(ParallelIslandsTest, BlocksSharingAStaticGroundGiveTheSameStateOnOneAndTwoThreads) {
  BlocksOnGround one, two;
  const PeakRows peak =
      ExpectOneAndTwoThreadsAgree(one.world(), two.world(), 1.0 / 120.0, kParallelSteps, 2);
  EXPECT_EQ(two.world().last_step_stats().rigid_bodies_coupled, 2);
  EXPECT_GT(peak.contact, 0) << "the blocks never touched";
}

TEST(ParallelIslandsTest, EverySceneOnTwoThreadsEndsInTheStateHashOfOneThread) {
  for (const SceneInfo& info : SceneRegistry()) {
    uint64_t hashes[2] = {0, 0};
    try {
      for (int t = 0; t < 2; ++t) {
        std::unique_ptr<Scene> scene = info.make();
        scene->world().SetThreadCount(t + 1);
        for (int i = 0; i < kParallelSceneSteps; ++i) scene->Step(info.default_dt);
        hashes[t] = scene->CalcStateHash();
      }
    } catch (const InputError& e) {
      std::printf("%s: skipped (%s)\n", info.name.c_str(), e.what());  // armadillo without data
      continue;
    }
    EXPECT_EQ(hashes[0], hashes[1]) << info.name;
  }
}

TEST(ParallelIslandsTest, ChangingTheThreadCountBetweenStepsChangesNoResult) {
  auto serial = MakeFourLimitedBeams();
  auto switched = MakeFourLimitedBeams();
  const double dt = 1.0 / 240.0;
  for (int step = 0; step < 4; ++step) {
    switched->world().SetThreadCount(step % 2 == 0 ? 2 : 1);
    serial->Step(dt);
    switched->Step(dt);
  }
  ExpectSameWorldState(serial->world(), switched->world());
}

TEST(ParallelIslandsTest, AFailingBodyThrowsTheErrorOfOneThreadAndEveryBodyIsBackAtTheStart) {
  // Bodies 1 and 3 exceed max_speed in their unconstrained step: one thread meets body 1 first.
  auto make = [] {
    std::vector<TetBeamScene::Beam> beams = TetBeamScene::DefaultBeams();
    beams[1].settings.max_speed = 1e-6;
    beams[3].settings.max_speed = 1e-6;
    return std::make_unique<TetBeamScene>(beams, 4, 1);
  };
  std::string messages[2];
  std::unique_ptr<TetBeamScene> scenes[2] = {make(), make()};
  for (int t = 0; t < 2; ++t) {
    scenes[t]->world().SetThreadCount(t + 1);
    try {
      scenes[t]->Step(1.0 / 240.0);
      ADD_FAILURE() << "no SimulationError with " << t + 1 << " threads";
    } catch (const SimulationError& e) {
      messages[t] = e.what();
    }
  }
  EXPECT_NE(messages[0].find("soft_5kPa'"), std::string::npos) << messages[0];
  EXPECT_EQ(messages[0], messages[1]);
  ExpectSameWorldState(scenes[0]->world(), scenes[1]->world());
}

TEST(ParallelIslandsTest, ThreadCountBelowOneIsRejected) {
  BulletWorldHolder holder;
  try {
    holder.world.SetThreadCount(0);
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("SetThreadCount: thread count must be >= 1, got 0"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(holder.world.thread_count(), 1);
  EXPECT_THROW(IslandThreadPool(-1), InputError);
}

TEST(IslandThreadPoolTest, RunsEveryTaskOnceAndRethrowsTheLowestFailure) {
  IslandThreadPool pool(2);
  EXPECT_EQ(pool.num_threads(), 2);
  std::vector<std::atomic<int>> runs(64);
  auto count = [&](int i) { runs[i].fetch_add(1); };
  for (int round = 0; round < 50; ++round) pool.Run(64, count);
  for (const auto& r : runs) EXPECT_EQ(r.load(), 50);

  std::vector<std::atomic<int>> ran(16);
  auto fail = [&](int i) {
    ran[i].fetch_add(1);
    if (i == 5 || i == 11) throw std::runtime_error("task " + std::to_string(i));
  };
  try {
    pool.Run(16, fail);
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "task 5");
  }
  for (const auto& r : ran) EXPECT_EQ(r.load(), 1);  // every task ran, also after the failure
  pool.Run(0, count);                                // no tasks: returns at once
}

}  // namespace
}  // namespace taut
