// World steps of multi-island scenes on 1 and 2 threads (DeformableWorld::SetThreadCount), in one
// run so their ratio is measured on the same machine state: four strain-limited tet beams (four
// islands with rows: stage 6 in parallel, and stage 2), and four unlimited ones (no rows: only the
// unconstrained steps of stage 2 in parallel). Median of 5 repetitions of wall time (real time:
// the work is on several threads) over the same 40 steps after the same warm-up. Only the
// simulation step is timed. And one hex ball alone, whose element loops the pool splits.
#include <benchmark/benchmark.h>

#include "demos/scenes/bullet_world_holder.h"
#include "demos/scenes/scene.h"
#include "demos/scenes/tet_beam_scene.h"
#include "plugin/hex_shapes.h"

namespace taut {
namespace {

// Four 1 x 0.2 x 0.2 m beams of cells_x x (cells_x / 5) x (cells_x / 5) cubes (6 tets each; 10:
// 240 tets), the tet_beam scene's limited materials twice, or its two unlimited ones twice.
std::unique_ptr<TetBeamScene> MakeFourBeams(bool limited, int cells_x) {
  const std::vector<TetBeamScene::Beam> beams = TetBeamScene::DefaultBeams();
  const TetBeamScene::Beam& a = limited ? beams[2] : beams[0];
  const TetBeamScene::Beam& b = limited ? beams[3] : beams[1];
  return std::make_unique<TetBeamScene>(std::vector<TetBeamScene::Beam>{a, b, b, a}, cells_x,
                                        cells_x / 5);
}

// range(0): threads, range(1): cells_x; steps after 30 warm-up steps, reporting islands and SQP
// iterations per step.
void RunFourBeams(benchmark::State& state, bool limited) {
  auto scene = MakeFourBeams(limited, static_cast<int>(state.range(1)));
  scene->world().SetThreadCount(static_cast<int>(state.range(0)));
  const double dt = 1.0 / 240.0;
  for (int i = 0; i < 30; ++i) scene->Step(dt);
  int steps = 0, sqp = 0, islands = 0;
  for (auto _ : state) {
    scene->Simulate(dt);
    sqp += scene->world().last_step_stats().sqp_iterations;
    islands += scene->world().last_step_stats().islands;
    ++steps;
  }
  state.counters["islands_solved"] = static_cast<double>(islands) / steps;
  state.counters["sqp_per_step"] = static_cast<double>(sqp) / steps;
}

void BM_ParallelStepFourLimitedBeams(benchmark::State& state) { RunFourBeams(state, true); }
void BM_ParallelStepFourUnlimitedBeams(benchmark::State& state) { RunFourBeams(state, false); }

BENCHMARK(BM_ParallelStepFourLimitedBeams)
    ->ArgNames({"threads", "cells"})
    ->Args({1, 10})
    ->Args({2, 10})
    ->Iterations(40)  // the same 40 steps for either thread count
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Repetitions(5)
    ->ReportAggregatesOnly(true);
BENCHMARK(BM_ParallelStepFourUnlimitedBeams)
    ->ArgNames({"threads", "cells"})
    ->ArgsProduct({{1, 2}, {10, 20}})
    ->Iterations(40)  // the same 40 steps for either thread count
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Repetitions(5)
    ->ReportAggregatesOnly(true);

// One body alone (no other body to step beside it): a soft hex ball of radius 1 m, cells of
// 1/range(1) m (7: 1,472 hexes), resting on its fixed bottom cap in free space; the pool splits its
// element loops (forces, rotations, assembly). range(0): threads. Wall time per world step.
void BM_ParallelStepOneHexBall(benchmark::State& state) {
  BulletWorldHolder holder;
  DeformableBodySettings settings = MakeSceneBodySettings("ball", 1e5, 1000.0);
  auto lattice = std::make_shared<HexLattice>(
      MakeSphereHexLattice(1.0, 1.0 / static_cast<double>(state.range(1))));
  DeformableBody* ball = holder.world.AddHexBody(lattice, settings);
  ball->FixNodesWhere([](const Vec3& X) { return X.z() < -0.7; });
  holder.world.SetThreadCount(static_cast<int>(state.range(0)));
  const double dt = 1.0 / 240.0;
  for (int i = 0; i < 5; ++i) holder.world.stepSimulation(dt, 1, dt);
  for (auto _ : state) holder.world.stepSimulation(dt, 1, dt);
  state.counters["hexes"] = ball->model().num_elements();
}
BENCHMARK(BM_ParallelStepOneHexBall)
    ->ArgNames({"threads", "cells_per_m"})
    ->ArgsProduct({{1, 2}, {4, 7}})
    ->Iterations(20)  // the same 20 steps for either thread count
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Repetitions(5)
    ->ReportAggregatesOnly(true);

}  // namespace
}  // namespace taut
