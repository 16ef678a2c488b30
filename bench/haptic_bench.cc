// The haptic loop against the full step it stands in for, on paper A's finger held pressed on the
// table by its bone (flat, anisotropic limits, 20 N; dt = 1 ms as the finger scene). Each
// iteration: one full step (stepSimulation), one Capture of the bone's loop, and 8 haptic queries
// with the bone moved 0..2 um further down (the 1 kHz ticks a slower step leaves to the loop).
// Counters, medians over the iteration's samples (Google Benchmark reports their medians over the
// repetitions):
//   ms_step      the full step [ms];  ms_capture  HapticForceLoop::Capture [ms]
//   us_query     one CalcToolWrench [us];  step_per_query  ms_step / us_query (same run)
//   sweeps       PGS sweeps per query;  rows  rows of the frozen LCP
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <memory>
#include <vector>

#include "bullet_bridge/haptic_force_loop.h"
#include "demos/scenes/finger_scene.h"

namespace taut {
namespace {

constexpr double kDt = 1e-3;
using Clock = std::chrono::steady_clock;

double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

double MsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// The flat anisotropic press stepped until the bone stops at 20 N, holding for 1 s after.
std::unique_ptr<FingerScene> MakeHeldFinger() {
  FingerSceneSettings settings;
  settings.target_force = 20.0;
  settings.hold_time = 1.0;
  auto scene = std::make_unique<FingerScene>(
      std::vector<FingerPress>{{FingerPressAxis::kFlat, FingerScene::Anisotropic()}}, settings);
  for (int step = 0; step < 2000 && scene->result(0).stop_reason.empty(); ++step) scene->Step(kDt);
  return scene;
}

void BM_HapticQueryVsFullStep(benchmark::State& state) {
  std::unique_ptr<FingerScene> scene = MakeHeldFinger();
  if (scene->result(0).stop_reason.empty()) {
    state.SkipWithError("the finger did not reach its force");
    return;
  }
  std::vector<double> ms_step, ms_capture, us_query, sweeps;
  int rows = 0;
  for (auto _ : state) {
    const auto t_step = Clock::now();
    scene->Simulate(kDt);
    ms_step.push_back(MsSince(t_step));
    const auto t_capture = Clock::now();
    HapticForceLoop loop = HapticForceLoop::Capture(scene->world(), scene->bone());
    ms_capture.push_back(MsSince(t_capture));
    rows = loop.lcp().size();
    for (int k = 1; k <= 8; ++k) {
      ToolMotion motion;
      motion.displacement = Vec3(0.0, 0.0, -0.25e-6 * k);
      const HapticWrench wrench = loop.CalcToolWrench(motion);
      benchmark::DoNotOptimize(wrench.force);
      us_query.push_back(wrench.microseconds);
      sweeps.push_back(wrench.sweeps);
    }
    scene->Measure(kDt);
  }
  state.counters["ms_step"] = Median(ms_step);
  state.counters["ms_capture"] = Median(ms_capture);
  state.counters["us_query"] = Median(us_query);
  state.counters["step_per_query"] = 1e3 * Median(ms_step) / Median(us_query);
  state.counters["sweeps"] = Median(sweeps);
  state.counters["rows"] = rows;
}
BENCHMARK(BM_HapticQueryVsFullStep)->Unit(benchmark::kMillisecond)->Iterations(50);

}  // namespace
}  // namespace taut
