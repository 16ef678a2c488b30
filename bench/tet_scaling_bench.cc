// Per-step time of the unconstrained tet beam (the cantilever of tet_beam_step_bench.cc: 1 x 0.2
// x 0.2 m, E = 200 kPa, nu = 0.3, 1000 kg/m^3, x = 0 end fixed, gravity) from ~200 to ~100,000
// tets, doubling the target count each size. scripts/run_bench.sh fits time ~ tets^p (log-log
// least squares) to the medians. Every size runs kTimedSteps steps after one warm-up step (its
// first factorization), so the figure is the mean cost of a step with factor reuse (most steps
// solve by PCG on a kept factor, some refactor: the `factored` counter gives their share).
// Repetitions come from the command line (scripts/run_bench.sh: 5, aggregates only).
#include <benchmark/benchmark.h>

#include <array>
#include <cmath>

#include "demos/scenes/bullet_world_holder.h"
#include "demos/scenes/tet_beam_scene.h"
#include "plugin/box_tet_mesher.h"

namespace taut {
namespace {

constexpr double kLength = 1.0;
constexpr double kWidth = 0.2;
constexpr int kTimedSteps = 24;

// Cells (nx, ny, nz) of a beam with about `target` tets (6 per cell), nx/ny and nx/nz as close to
// the beam's aspect 5 as the count allows: ny, nz in {n, n + 1} with n >= 2, nx from the count.
std::array<int, 3> CalcBeamCells(int target) {
  std::array<int, 3> best{0, 0, 0};
  double best_cost = HUGE_VAL;
  for (int n = 2; n <= 40; ++n) {
    for (int extra = 0; extra <= 1; ++extra) {
      const int ny = n, nz = n + extra;
      const int nx = std::max(1, static_cast<int>(std::lround(target / (6.0 * ny * nz))));
      // Count off by a log ratio costs 4x as much as shape off by the same log ratio.
      const double count_error = std::abs(std::log(6.0 * nx * ny * nz / target));
      const double shape_error = std::abs(std::log(nx / (2.5 * (ny + nz))));
      const double cost = 4.0 * count_error + shape_error;
      if (cost < best_cost) best_cost = cost, best = {nx, ny, nz};
    }
  }
  return best;
}

// Steps the beam of ~range(0) tets (after one warm-up step) and reports the actual tet count.
void BM_TetBeamScaling(benchmark::State& state) {
  const std::array<int, 3> cells = CalcBeamCells(static_cast<int>(state.range(0)));
  BulletWorldHolder holder;
  auto mesh = std::make_shared<TetMesh>(
      MakeBoxTetMesh(Vec3(kLength, kWidth, kWidth), cells[0], cells[1], cells[2]));
  mesh->source = "scaling beam";
  DeformableBody* body = holder.world.AddTetBody(mesh, TetBeamScene::DefaultBeams()[0].settings);
  body->FixNodesWhere([](const Vec3& X) { return X.x() < 1e-9; });
  const double dt = 1.0 / 240.0;
  holder.world.stepSimulation(dt, 1, dt);
  int factored = 0, pcg_iterations = 0;
  for (auto _ : state) {
    holder.world.stepSimulation(dt, 1, dt);
    if (body->last_pcg_iterations() == 0) ++factored;
    pcg_iterations += body->last_pcg_iterations();
  }
  state.counters["factored"] = static_cast<double>(factored) / kTimedSteps;
  state.counters["pcg_iterations"] = static_cast<double>(pcg_iterations) / kTimedSteps;
  state.counters["supernodal"] = body->system().uses_supernodal_factor() ? 1.0 : 0.0;
  state.counters["tets"] = static_cast<double>(mesh->tets.size());
  state.counters["dofs"] = 3.0 * static_cast<double>(mesh->nodes.size());
  state.counters["cells_x"] = cells[0];
  state.counters["cells_y"] = cells[1];
  state.counters["cells_z"] = cells[2];
}

// Targets 200 * 2^k tets, k = 0..9 (200 to 102,400).
void ScalingSizes(benchmark::internal::Benchmark* bench) {
  for (int k = 0; k <= 9; ++k) bench->Arg(200 << k);
}

BENCHMARK(BM_TetBeamScaling)
    ->Apply(ScalingSizes)
    ->Iterations(kTimedSteps)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace taut
