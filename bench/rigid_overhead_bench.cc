// A pure rigid scene (ground, 20 boxes in a stack, 20 spheres) stepped by stock
// btDiscreteDynamicsWorld and by taut's DeformableWorld, in one run: taut must add no cost when a
// scene has no deformable body. Median of 5 repetitions.
#include <benchmark/benchmark.h>
#include <btBulletDynamicsCommon.h>

#include <memory>
#include <vector>

#include "bullet_bridge/deformable_world.h"

namespace taut {
namespace {

template <typename World>
struct RigidPile {
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher{&configuration};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  World world{&dispatcher, &broadphase, &solver, &configuration};
  btStaticPlaneShape plane{btVector3(0, 0, 1), 0};
  btBoxShape box{btVector3(0.2, 0.2, 0.2)};
  btSphereShape sphere{0.2};
  std::vector<std::unique_ptr<btDefaultMotionState>> states;
  std::vector<std::unique_ptr<btRigidBody>> bodies;

  void Add(btCollisionShape* shape, double mass, const btVector3& at) {
    btVector3 inertia(0, 0, 0);
    if (mass > 0) shape->calculateLocalInertia(mass, inertia);
    states.push_back(std::make_unique<btDefaultMotionState>(btTransform::getIdentity()));
    states.back()->setWorldTransform(btTransform(btQuaternion::getIdentity(), at));
    bodies.push_back(std::make_unique<btRigidBody>(mass, states.back().get(), shape, inertia));
    world.addRigidBody(bodies.back().get());
  }
  RigidPile() {
    world.setGravity(btVector3(0, 0, -9.81));
    Add(&plane, 0, btVector3(0, 0, 0));
    for (int i = 0; i < 20; ++i) Add(&box, 1.0, btVector3(0, 0, 0.2 + 0.41 * i));
    for (int i = 0; i < 20; ++i)
      Add(&sphere, 1.0, btVector3(1 + 0.1 * i, 0.5 * (i % 3), 1 + 0.5 * i));
  }
  ~RigidPile() {
    for (auto& body : bodies) world.removeRigidBody(body.get());
  }
};

// 60 substeps of 1/240 s per iteration, after 60 warm-up substeps.
template <typename World>
void RunPile(benchmark::State& state) {
  RigidPile<World> pile;
  for (int i = 0; i < 60; ++i) pile.world.stepSimulation(1.0 / 240.0, 1, 1.0 / 240.0);
  for (auto _ : state)
    for (int i = 0; i < 60; ++i) pile.world.stepSimulation(1.0 / 240.0, 1, 1.0 / 240.0);
}

void BM_RigidPileStockBullet(benchmark::State& state) { RunPile<btDiscreteDynamicsWorld>(state); }
void BM_RigidPileTautWorld(benchmark::State& state) { RunPile<DeformableWorld>(state); }

BENCHMARK(BM_RigidPileStockBullet)
    ->Unit(benchmark::kMillisecond)
    ->Repetitions(5)
    ->ReportAggregatesOnly(true);
BENCHMARK(BM_RigidPileTautWorld)
    ->Unit(benchmark::kMillisecond)
    ->Repetitions(5)
    ->ReportAggregatesOnly(true);

}  // namespace
}  // namespace taut
