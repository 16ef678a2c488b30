// Per-step time of the tet beam cantilever (paper A Fig. 2 geometry) at two resolutions:
// the unconstrained implicit step, and the same beam with an active isotropic strain limit, in
// one run so their ratio is measured on the same machine state. Median of 5 repetitions.
#include <benchmark/benchmark.h>

#include "demos/scenes/tet_beam_scene.h"

namespace taut {
namespace {

// One beam of cells_x x (cells_x / 5) x (cells_x / 5) cubes, 6 tets each.
std::unique_ptr<TetBeamScene> MakeScene(int cells_x, bool limited) {
  auto beams = TetBeamScene::DefaultBeams();
  std::vector<TetBeamScene::Beam> one = {limited ? beams[3] : beams[0]};
  return std::make_unique<TetBeamScene>(one, cells_x, cells_x / 5);
}

// Steps the scene (after 30 warm-up steps) and reports tets and SQP figures.
void RunSteps(benchmark::State& state, bool limited) {
  auto scene = MakeScene(static_cast<int>(state.range(0)), limited);
  const double dt = 1.0 / 240.0;
  for (int i = 0; i < 30; ++i) scene->Step(dt);
  int steps = 0, sqp = 0;
  for (auto _ : state) {
    scene->Step(dt);
    sqp += scene->world().last_step_stats().sqp_iterations;
    ++steps;
  }
  state.counters["tets"] = scene->world().deformable_body(0).model().num_elements();
  state.counters["sqp_per_step"] = static_cast<double>(sqp) / steps;
}

void BM_TetBeamStepUnconstrained(benchmark::State& state) { RunSteps(state, false); }
void BM_TetBeamStepIsotropicLimit(benchmark::State& state) { RunSteps(state, true); }

BENCHMARK(BM_TetBeamStepUnconstrained)
    ->Arg(10)
    ->Arg(20)
    ->Unit(benchmark::kMillisecond)
    ->Repetitions(5)
    ->ReportAggregatesOnly(true);
BENCHMARK(BM_TetBeamStepIsotropicLimit)
    ->Arg(10)
    ->Unit(benchmark::kMillisecond)
    ->Repetitions(5)
    ->ReportAggregatesOnly(true);

}  // namespace
}  // namespace taut
