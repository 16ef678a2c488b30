// World snapshots (bullet_bridge/world_snapshot.h): a world restored from a snapshot continues
// bit for bit like the uninterrupted run, by the state hash of the determinism pins
// (Scene::CalcStateHash, tests/determinism_test.cc), whatever the world did in between; a
// snapshot of another world is refused and changes nothing.
#include <gtest/gtest.h>

#include <string>

#include "demos/scenes/scene.h"
#include "plugin/box_tet_mesher.h"
#include "plugin/hex_shapes.h"

namespace taut {
namespace {

// stepSimulation's time per call and fixed substep [s]: 2.4 substeps per call, so the world
// carries a remainder of unsimulated time from call to call.
constexpr double kFrame = 1.0 / 100.0;
constexpr double kSubstep = 1.0 / 240.0;
constexpr int kCallsBefore = 12;  // calls before the snapshot (the body lands, the box hits it)
constexpr int kCallsAfter = 12;   // calls after it, compared bit for bit

// A scene for its world and state hash only.
class TestScene : public Scene {
 public:
  BulletWorldHolder& holder() { return holder_; }
  void WriteFigures(nlohmann::json& /*figures*/) const override {}
};

void RunCalls(Scene& scene, int calls) {
  for (int i = 0; i < calls; ++i) scene.world().stepSimulation(kFrame, 4, kSubstep);
}

// Settings of a soft body [Pa, -, kg/m^3].
DeformableBodySettings SoftSettings(const std::string& name) {
  DeformableBodySettings settings;
  settings.name = name;
  settings.material = {60e3, 0.3, 1000.0};
  return settings;
}

// A rigid box 0.1 m wide sliding at 1.5 m/s into the deformable, with a smaller box on it (a
// sphere instead: `sphere_on_top`): its contacts with the ground and the top box are Bullet
// manifolds inside the deformable's island.
void AddSlidingBoxes(BulletWorldHolder& holder, bool sphere_on_top = false) {
  btRigidBody* box = holder.AddRigidBody(std::make_unique<btBoxShape>(btVector3(0.05, 0.05, 0.05)),
                                         1.0, btVector3(-0.12, 0.05, 0.05), 0.6);
  box->setLinearVelocity(btVector3(1.5, 0, 0));
  std::unique_ptr<btCollisionShape> top;
  if (sphere_on_top)
    top = std::make_unique<btSphereShape>(0.03);
  else
    top = std::make_unique<btBoxShape>(btVector3(0.03, 0.03, 0.03));
  holder.AddRigidBody(std::move(top), 0.2, btVector3(-0.12, 0.05, 0.131), 0.6);
}

// A strain-limited tet beam (0.3 x 0.1 x 0.1 m, `cells_x` x 1 x 1 cubes) dropped from 2 cm onto
// the ground, hit by the boxes, and a tet cube falling onto it from 25 cm (its own island until
// it lands, after the snapshot: then the pair's contact source is made); `solver` picks the
// island path.
std::unique_ptr<TestScene> MakeTetScene(IslandSolverKind solver, int cells_x = 4,
                                        bool sphere_on_top = false) {
  auto scene = std::make_unique<TestScene>();
  BulletWorldHolder& holder = scene->holder();
  holder.AddStaticGround(0.8);
  DeformableBody* beam = holder.world.AddTetBody(
      MakeBoxTetMesh(Vec3(0.3, 0.1, 0.1), cells_x, 1, 1), SoftSettings("beam"),
      btTransform(btQuaternion::getIdentity(), btVector3(0, 0, 0.02)));
  holder.world.SetStrainLimits(beam, StrainLimitSettings::Isotropic(0.97, 1.03));
  holder.world.AddTetBody(MakeBoxTetMesh(Vec3(0.06, 0.06, 0.06), 1, 1, 1), SoftSettings("cube"),
                          btTransform(btQuaternion::getIdentity(), btVector3(0.15, 0.02, 0.25)));
  AddSlidingBoxes(holder, sphere_on_top);
  holder.world.mutable_solver_settings().solver = solver;
  return scene;
}

// An energy-limited hex cylinder (0.3 m long, radius 0.05 m) dropped onto the ground, hit by
// the boxes.
std::unique_ptr<TestScene> MakeHexScene(IslandSolverKind solver) {
  auto scene = std::make_unique<TestScene>();
  BulletWorldHolder& holder = scene->holder();
  holder.AddStaticGround(0.8);
  DeformableBody* cylinder =
      holder.world.AddHexBody(MakeCylinderHexLattice(0.3, 0.05, 0.05), SoftSettings("cylinder"),
                              btTransform(btQuaternion::getIdentity(), btVector3(0, 0.05, 0.07)));
  holder.world.SetEnergyLimits(cylinder, EnergyLimitSettings::PerElementEnergy(2e-3));
  AddSlidingBoxes(holder);
  holder.world.mutable_solver_settings().solver = solver;
  return scene;
}

using SceneMaker = std::function<std::unique_ptr<TestScene>()>;

// The state hash after kCallsBefore + kCallsAfter calls, uninterrupted.
uint64_t RunUninterrupted(const SceneMaker& make) {
  std::unique_ptr<TestScene> scene = make();
  RunCalls(*scene, kCallsBefore + kCallsAfter);
  return scene->CalcStateHash();
}

// Throws the world off its course: the boxes fly, the deformable is kicked and a node fixed, and
// the world steps on (the manifolds, warm starts and node kinds all differ afterwards).
void Diverge(TestScene& scene) {
  DeformableWorld& world = scene.world();
  for (int i = 0; i < world.getNumCollisionObjects(); ++i) {
    btRigidBody* rigid = btRigidBody::upcast(world.getCollisionObjectArray()[i]);
    if (rigid != nullptr && rigid->getInvMass() > 0.0)
      rigid->setLinearVelocity(btVector3(-2.0, 1.0, 3.0 + i));
  }
  DeformableBody& body = world.deformable_body(0);
  for (int n = 0; n < body.num_nodes(); ++n) body.AddNodeForce(n, Vec3(0, 0, 40.0));
  body.FixNodes({0});
  RunCalls(scene, 20);
  body.AddNodeForce(1, Vec3(5.0, 0, 0));  // queued for the next step, dropped by the restore
}

class WorldSnapshotTest : public testing::TestWithParam<IslandSolverKind> {};

TEST_P(WorldSnapshotTest, RestoredTetWorldContinuesBitIdenticallyAndReusesItsSourceIds) {
  const SceneMaker make = [] { return MakeTetScene(GetParam()); };
  const uint64_t uninterrupted = RunUninterrupted(make);
  std::unique_ptr<TestScene> scene = make();
  RunCalls(*scene, kCallsBefore);
  const WorldSnapshot snapshot = scene->world().SaveSnapshot();
  // The body is on the ground and the box against it: the snapshot holds warm starts.
  ASSERT_GT(scene->world().last_step_stats().rows_contact, 0);
  ASSERT_GT(scene->world().last_step_stats().rows_rigid_contact, 0);
  ASSERT_FALSE(snapshot.deformables[0].solver.warm.empty());
  RunCalls(*scene, kCallsAfter);
  EXPECT_EQ(scene->CalcStateHash(), uninterrupted) << "saving changed the run";
  const WorldSnapshot end = scene->world().SaveSnapshot();

  scene->world().RestoreSnapshot(snapshot);
  RunCalls(*scene, kCallsAfter);
  EXPECT_EQ(scene->CalcStateHash(), uninterrupted);
  // The restored world handed out the same row-key source ids as the first run did.
  const WorldSnapshot again = scene->world().SaveSnapshot();
  EXPECT_EQ(again.next_source_id, end.next_source_id);
  EXPECT_EQ(again.island_source_ids, end.island_source_ids);
}

TEST_P(WorldSnapshotTest, RestoreAfterDivergingContinuesBitIdentically) {
  const SceneMaker make = [] { return MakeTetScene(GetParam()); };
  const uint64_t uninterrupted = RunUninterrupted(make);
  std::unique_ptr<TestScene> scene = make();
  RunCalls(*scene, kCallsBefore);
  const WorldSnapshot snapshot = scene->world().SaveSnapshot();
  Diverge(*scene);
  ASSERT_NE(scene->CalcStateHash(), uninterrupted);
  scene->world().RestoreSnapshot(snapshot);
  EXPECT_EQ(scene->world().deformable_body(0).node_kind(0), NodeKind::kFree);
  EXPECT_EQ(scene->world().deformable_body(0).node_external_force(1), Vec3::Zero());
  RunCalls(*scene, kCallsAfter);
  EXPECT_EQ(scene->CalcStateHash(), uninterrupted);
}

TEST_P(WorldSnapshotTest, SnapshotRestoresIntoAnotherWorldBuiltTheSameWay) {
  const SceneMaker make = [] { return MakeTetScene(GetParam()); };
  const uint64_t uninterrupted = RunUninterrupted(make);
  std::unique_ptr<TestScene> source = make();
  RunCalls(*source, kCallsBefore);
  const WorldSnapshot snapshot = source->world().SaveSnapshot();
  // A fresh world and one that ran elsewhere.
  std::unique_ptr<TestScene> fresh = make();
  std::unique_ptr<TestScene> diverged = make();
  Diverge(*diverged);
  for (TestScene* target : {fresh.get(), diverged.get()}) {
    target->world().RestoreSnapshot(snapshot);
    EXPECT_EQ(target->CalcStateHash(), source->CalcStateHash());
    RunCalls(*target, kCallsAfter);
    EXPECT_EQ(target->CalcStateHash(), uninterrupted);
  }
}

TEST_P(WorldSnapshotTest, SnapshotSavedIntoAUsedOneRestoresLikeAFreshOne) {
  const SceneMaker make = [] { return MakeTetScene(GetParam()); };
  const uint64_t uninterrupted = RunUninterrupted(make);
  // The object first holds a state of a world that ran elsewhere on the other path: other
  // warm starts, contacts and Newton matrices (the primal path analyzes H, the dual one not).
  const IslandSolverKind other =
      GetParam() == IslandSolverKind::kPrimal ? IslandSolverKind::kDual : IslandSolverKind::kPrimal;
  std::unique_ptr<TestScene> elsewhere = MakeTetScene(other);
  RunCalls(*elsewhere, kCallsBefore + kCallsAfter);
  WorldSnapshot snapshot;
  elsewhere->world().SaveSnapshot(snapshot);
  ASSERT_FALSE(snapshot.deformables[0].solver.warm.empty());

  std::unique_ptr<TestScene> scene = make();
  RunCalls(*scene, kCallsBefore);
  scene->world().SaveSnapshot(snapshot);
  const WorldSnapshot fresh = scene->world().SaveSnapshot();
  for (size_t b = 0; b < fresh.deformables.size(); ++b) {
    const WorldSnapshot::Deformable& reused = snapshot.deformables[b];
    EXPECT_EQ(reused.body.x, fresh.deformables[b].body.x);
    EXPECT_EQ(reused.body.newton.analyzed, fresh.deformables[b].body.newton.analyzed);
    EXPECT_EQ(reused.solver.warm, fresh.deformables[b].solver.warm);
  }
  EXPECT_EQ(snapshot.pair_contacts.size(), fresh.pair_contacts.size());
  EXPECT_EQ(snapshot.forces.contacts, fresh.forces.contacts);
  EXPECT_EQ(snapshot.forces.limits, fresh.forces.limits);
  Diverge(*scene);
  scene->world().RestoreSnapshot(snapshot);
  RunCalls(*scene, kCallsAfter);
  EXPECT_EQ(scene->CalcStateHash(), uninterrupted);
}

TEST_P(WorldSnapshotTest, RestoredHexWorldContinuesBitIdentically) {
  const SceneMaker make = [] { return MakeHexScene(GetParam()); };
  const uint64_t uninterrupted = RunUninterrupted(make);
  std::unique_ptr<TestScene> scene = make();
  RunCalls(*scene, kCallsBefore);
  const WorldSnapshot snapshot = scene->world().SaveSnapshot();
  ASSERT_GT(scene->world().last_step_stats().rows_contact, 0);
  Diverge(*scene);
  scene->world().RestoreSnapshot(snapshot);
  RunCalls(*scene, kCallsAfter);
  EXPECT_EQ(scene->CalcStateHash(), uninterrupted);
}

INSTANTIATE_TEST_SUITE_P(WorldSnapshot, WorldSnapshotTest,
                         testing::Values(IslandSolverKind::kAuto, IslandSolverKind::kPrimal),
                         [](const testing::TestParamInfo<IslandSolverKind>& info) {
                           return std::string(GetIslandSolverName(info.param));
                         });

// Restores `snapshot` into `scene`, expecting an InputError whose message contains `what`, and
// checks that the scene then runs exactly like an untouched copy made by `make`.
void ExpectRefusedAndUntouched(const WorldSnapshot& snapshot, TestScene& scene,
                               const SceneMaker& make, const std::string& what) {
  const uint64_t before = scene.CalcStateHash();
  try {
    scene.world().RestoreSnapshot(snapshot);
    ADD_FAILURE() << "restore of a foreign snapshot did not throw (" << what << ")";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find(what), std::string::npos) << error.what();
  }
  EXPECT_EQ(scene.CalcStateHash(), before);
  std::unique_ptr<TestScene> untouched = make();
  RunCalls(*untouched, kCallsBefore);
  RunCalls(scene, kCallsAfter);
  RunCalls(*untouched, kCallsAfter);
  EXPECT_EQ(scene.CalcStateHash(), untouched->CalcStateHash()) << what;
}

TEST(WorldSnapshotMismatchTest, SnapshotOfAnotherWorldIsRefusedAndChangesNothing) {
  std::unique_ptr<TestScene> source = MakeTetScene(IslandSolverKind::kAuto);
  RunCalls(*source, kCallsBefore);
  const WorldSnapshot snapshot = source->world().SaveSnapshot();

  // Another mesh resolution: the body's node count differs.
  const SceneMaker finer = [] { return MakeTetScene(IslandSolverKind::kAuto, 8); };
  std::unique_ptr<TestScene> scene = finer();
  RunCalls(*scene, kCallsBefore);
  const DeformableBody& saved_beam = source->world().deformable_body(0);
  const DeformableBody& finer_beam = scene->world().deformable_body(0);
  ExpectRefusedAndUntouched(
      snapshot, *scene, finer,
      internal::Concat("deformable body 0 ('beam') has ", finer_beam.num_nodes(), " nodes and ",
                       finer_beam.num_elements(), " elements, in the snapshot ",
                       saved_beam.num_nodes(), " nodes and ", saved_beam.num_elements(),
                       " elements"));

  // One rigid body more.
  const SceneMaker extra = [] {
    std::unique_ptr<TestScene> s = MakeTetScene(IslandSolverKind::kAuto);
    s->holder().AddRigidBody(std::make_unique<btSphereShape>(0.05), 1.0, btVector3(1, 1, 0.05));
    return s;
  };
  scene = extra();
  RunCalls(*scene, kCallsBefore);
  const int num_objects = source->world().getNumCollisionObjects();
  ExpectRefusedAndUntouched(snapshot, *scene, extra,
                            internal::Concat("the world has ", num_objects + 1,
                                             " collision objects, the snapshot ", num_objects));

  // The same count with another shape in place of the top box.
  const SceneMaker other_shape = [] { return MakeTetScene(IslandSolverKind::kAuto, 4, true); };
  scene = other_shape();
  RunCalls(*scene, kCallsBefore);
  ExpectRefusedAndUntouched(
      snapshot, *scene, other_shape,
      internal::Concat("collision object ", num_objects - 1,
                       " is a rigid body of shape SPHERE (type ", SPHERE_SHAPE_PROXYTYPE,
                       "), in the snapshot a rigid body of shape Box (type ", BOX_SHAPE_PROXYTYPE,
                       ")"));

  // No deformable at all.
  const SceneMaker rigid_only = [] {
    auto s = std::make_unique<TestScene>();
    s->holder().AddStaticGround(0.8);
    AddSlidingBoxes(s->holder());
    return s;
  };
  scene = rigid_only();
  RunCalls(*scene, kCallsBefore);
  ExpectRefusedAndUntouched(snapshot, *scene, rigid_only,
                            internal::Concat("the world has 0 deformable bodies, the snapshot ",
                                             source->world().num_deformable_bodies()));
}

// The registered demo scenes that only step their world (no drivers of their own): a stack of
// three boxes on a soft hex sphere (several rigid manifolds in one island) and a falling hex ball.
TEST(WorldSnapshotSceneTest, DemoScenesContinueBitIdentically) {
  for (const char* name : {"box_on_sphere", "falling_sphere"}) {
    const SceneInfo& info = FindScene(name);
    std::unique_ptr<Scene> reference = info.make();
    for (int i = 0; i < 2 * kCallsAfter; ++i) reference->Simulate(info.default_dt);
    std::unique_ptr<Scene> scene = info.make();
    for (int i = 0; i < kCallsAfter; ++i) scene->Simulate(info.default_dt);
    const WorldSnapshot snapshot = scene->world().SaveSnapshot();
    for (int i = 0; i < kCallsAfter; ++i) scene->Simulate(info.default_dt);
    scene->world().RestoreSnapshot(snapshot);
    for (int i = 0; i < kCallsAfter; ++i) scene->Simulate(info.default_dt);
    EXPECT_EQ(scene->CalcStateHash(), reference->CalcStateHash()) << name;
  }
}

}  // namespace
}  // namespace taut
