// Cost of face contact (DeformableBodySettings::face_contact, docs/math.md §5.5) in one row
// collection: a soft slab of n x n x 2 cells (0.05 m) under a resting sphere of radius 0.07 m,
// RigidContactSource::AppendIslandRows with point contact only and with face contact, in the
// same run (the ratio of the two medians is the price of the faces).
//   taut_bench --benchmark_filter='BM_FaceContactRows'
#include <benchmark/benchmark.h>
#include <btBulletDynamicsCommon.h>

#include <memory>
#include <vector>

#include "bullet_bridge/rigid_contact_source.h"
#include "constraints/deformable_island_body.h"
#include "plugin/box_tet_mesher.h"
#include "plugin/tet_element_model.h"

namespace taut {
namespace {

void RunFaceContactRows(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const bool faces = state.range(1) != 0;
  const double cell = 0.05, h = 1.0 / 240.0;
  DeformableBodySettings settings;
  settings.material = {1e5, 0.3, 1000.0};
  auto mesh = std::make_shared<const TetMesh>(
      MakeBoxTetMesh(Vec3(n * cell, n * cell, 2 * cell), n, n, 2, Vec3::Zero()));
  DeformableBody body(std::make_unique<TetElementModel>(mesh, settings.material), settings);
  body.BeginStep(h, Vec3::Zero());
  // A static sphere resting 1 mm into the middle of the top face, off its nodes.
  btSphereShape sphere(0.07);
  btCollisionObject object;
  object.setCollisionShape(&sphere);
  const double middle = 0.5 * n * cell + 0.013;
  object.setWorldTransform(
      btTransform(btQuaternion::getIdentity(), btVector3(middle, middle, 2 * cell + 0.069)));
  RigidContactSource source(body, MakeBodyContactSurface(body.model()), 1, 0.5, 0.01);
  source.set_face_contact(faces);
  source.set_objects({&object});
  DeformableIslandBody island(body);
  const std::vector<IslandBody*> bodies = {&island};
  const std::vector<VecX> v = {VecX::Zero(3 * body.num_nodes())};
  std::vector<VecX> x(1);
  island.CalcPositions(h, v[0], x[0]);
  std::vector<ConstraintRow> rows;
  for (auto _ : state) {
    rows.clear();
    source.AppendIslandRows(IslandIterate(h, bodies, v, x), rows);
    benchmark::DoNotOptimize(rows.data());
  }
  state.counters["triangles"] =
      static_cast<double>(MakeBodyContactSurface(body.model()).triangles.size());
  state.counters["rows"] = static_cast<double>(rows.size());
}

BENCHMARK(RunFaceContactRows)
    ->Name("BM_FaceContactRows")
    ->ArgNames({"n", "faces"})
    ->ArgsProduct({{8, 32}, {0, 1}})
    ->Repetitions(5)
    ->ReportAggregatesOnly(true);

}  // namespace
}  // namespace taut
