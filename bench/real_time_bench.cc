// Issue 12's real-time figures on the demo scenes themselves (targets: the finger <= 1 ms per step
// at h = 1 ms in every press; the armadillo <= 2 ms per body per 1/60 s frame):
//   BM_RealTimeFinger            the finger scene's 520 steps of 1 ms (every press, its bone
//                                retreats included), each Simulate timed by thread CPU time; the
//                                scene's Measure (press logic, reactions) runs outside the timed
//                                region.
//   BM_RealTimeArmadillo/threads/steps_per_frame
//                                the armadillo scene (three 368-hex bodies, three islands) for 1 s:
//                                the drop, the impact at ~0.3 s and the toppling, at h = 1/240
//                                (4 steps per 1/60 s frame, the scene's default) or h = 1/60 (one
//                                step per frame), on 1 or 2 threads (DeformableWorld threads:
//                                islands and bodies in parallel, bitwise the same results).
// Counters per repetition (Google Benchmark reports their medians over the repetitions):
//   finger: step_median_ms, step_p99_ms, step_max_ms (thread CPU per Simulate), steps_over_1ms
//           (of `steps`), unconverged;
//   armadillo: frame_ms_per_body (median over the frames of the wall time of a frame's steps /
//           3), frame_max_ms_per_body, unconverged (steps).
// The armadillo needs data/armadillo.off (scripts/fetch_armadillo.sh); without it the benchmark
// reports an error and the others run.
#include <benchmark/benchmark.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <memory>
#include <vector>

#include "demos/scenes/armadillo_scene.h"
#include "demos/scenes/finger_scene.h"

namespace taut {
namespace {

double ThreadCpuMs() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
}

// The q-quantile (0 <= q <= 1) of v by the nearest rank.
double Quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const size_t rank = static_cast<size_t>(std::ceil(q * static_cast<double>(v.size())));
  return v[std::min(v.size() - 1, rank > 0 ? rank - 1 : 0)];
}

constexpr int kFingerSteps = 520;  // the scene's default run: every press
constexpr double kFingerDt = 1e-3;

void BM_RealTimeFinger(benchmark::State& state) {
  std::vector<double> step_ms;
  int unconverged = 0;
  for (auto _ : state) {
    state.PauseTiming();
    FingerScene scene(FingerScene::DefaultPresses());
    step_ms.clear();
    unconverged = 0;
    state.ResumeTiming();
    for (int i = 0; i < kFingerSteps; ++i) {
      const double t0 = ThreadCpuMs();
      scene.Simulate(kFingerDt);
      step_ms.push_back(ThreadCpuMs() - t0);
      state.PauseTiming();
      if (!scene.last_step_stats().converged) ++unconverged;
      scene.Measure(kFingerDt);
      state.ResumeTiming();
    }
  }
  state.counters["steps"] = kFingerSteps;
  state.counters["step_median_ms"] = Quantile(step_ms, 0.5);
  state.counters["step_p99_ms"] = Quantile(step_ms, 0.99);
  state.counters["step_max_ms"] = Quantile(step_ms, 1.0);
  state.counters["steps_over_1ms"] = static_cast<double>(
      std::count_if(step_ms.begin(), step_ms.end(), [](double ms) { return ms > 1.0; }));
  state.counters["unconverged"] = unconverged;
}
BENCHMARK(BM_RealTimeFinger)
    ->Iterations(1)
    ->Repetitions(3)
    ->Unit(benchmark::kMillisecond)
    ->ReportAggregatesOnly(true);

constexpr double kFrame = 1.0 / 60.0;
constexpr int kArmadilloFrames = 60;  // 1 s

// range(0): threads, range(1): steps per 1/60 s frame.
void BM_RealTimeArmadillo(benchmark::State& state) {
  const int threads = static_cast<int>(state.range(0));
  const int steps_per_frame = static_cast<int>(state.range(1));
  const double dt = kFrame / steps_per_frame;
  std::vector<double> frame_ms;
  int unconverged = 0, bodies = 0;
  for (auto _ : state) {
    state.PauseTiming();
    std::unique_ptr<ArmadilloScene> scene;
    try {
      scene = std::make_unique<ArmadilloScene>(ArmadilloScene::DefaultMaterials());
    } catch (const std::exception& e) {
      state.SkipWithError(e.what());  // data/armadillo.off missing
      break;
    }
    scene->SetThreadCount(threads);
    bodies = scene->num_deformable_bodies();
    frame_ms.clear();
    unconverged = 0;
    state.ResumeTiming();
    for (int f = 0; f < kArmadilloFrames; ++f) {
      double ms = 0.0;
      for (int s = 0; s < steps_per_frame; ++s) {
        const auto t0 = std::chrono::steady_clock::now();
        scene->Simulate(dt);
        ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                  .count();
        state.PauseTiming();
        if (!scene->last_step_stats().converged) ++unconverged;
        scene->Measure(dt);
        state.ResumeTiming();
      }
      frame_ms.push_back(ms / bodies);
    }
  }
  if (bodies == 0) return;
  state.counters["bodies"] = bodies;
  state.counters["frame_ms_per_body"] = Quantile(frame_ms, 0.5);
  state.counters["frame_max_ms_per_body"] = Quantile(frame_ms, 1.0);
  state.counters["unconverged"] = unconverged;
}
BENCHMARK(BM_RealTimeArmadillo)
    ->ArgNames({"threads", "steps_per_frame"})
    ->ArgsProduct({{1, 2}, {4, 1}})
    ->Iterations(1)
    ->Repetitions(3)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->ReportAggregatesOnly(true);

}  // namespace
}  // namespace taut
