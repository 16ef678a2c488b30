// taut-haptic: paper A's finger pressed onto the table by its bone, stepped at the full step rate
// while a haptic loop (bullet_bridge/haptic_force_loop.h) answers the force on the bone at 1 kHz
// from the last step's frozen LCP, the bone moving on between steps. Writes DIR/haptic.csv (one
// row per step and per haptic tick) and prints the timings (docs/haptics.md).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <vector>

#include "bullet_bridge/haptic_force_loop.h"
#include "demos/scenes/finger_scene.h"

namespace {

using Clock = std::chrono::steady_clock;

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

double MsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// The table's force from the finger in the last step (contact report), z component [N].
double ReportedTableForce(const taut::DeformableWorld& world, const btCollisionObject* table) {
  for (const taut::RigidBodyWrench& wrench : world.last_rigid_wrenches())
    if (wrench.object == table) return wrench.force.z();
  return 0.0;
}

// The bone's pose a fraction s of the way from `from` to `to` (it only translates).
btTransform Interpolate(const btTransform& from, const btTransform& to, double s) {
  btTransform pose = from;
  pose.setOrigin(from.getOrigin().lerp(to.getOrigin(), static_cast<btScalar>(s)));
  return pose;
}

// What the run measured.
struct HapticRun {
  // |last tick's force - the next step's| / |the step's| over the steps the bone moved in
  std::vector<double> ms_step, ms_capture, us_query, prediction_error;
  int steps = 0, queries = 0;
};

// Steps the press; between steps, `ticks` haptic queries on the loop of the step before with the
// bone interpolated towards its next pose. One CSV row per step and per tick.
HapticRun RunPress(taut::FingerScene& scene, double dt, int ticks, int max_steps,
                   std::ofstream& csv) {
  HapticRun run;
  taut::HapticForceLoop loop;
  bool have_loop = false;
  double last_tick_force = 0.0;
  for (int step = 1; step <= max_steps && scene.current_press() < scene.num_presses(); ++step) {
    const btTransform before = scene.bone()->getWorldTransform();
    const auto t_step = Clock::now();
    scene.Simulate(dt);
    run.ms_step.push_back(MsSince(t_step));
    const btTransform after = scene.bone()->getWorldTransform();
    const double t0 = (step - 1) * dt;
    // The haptic ticks of (t0, t0 + dt] on the last step's loop, the bone where the device is.
    for (int k = 1; have_loop && k <= ticks; ++k) {
      const taut::HapticWrench w =
          loop.CalcToolWrench(Interpolate(before, after, double(k) / ticks));
      run.us_query.push_back(w.microseconds);
      ++run.queries;
      last_tick_force = w.force.z();
      csv << t0 + k * dt / ticks << ",1," << w.force.z() << ",," << w.sweeps << ","
          << w.microseconds << "\n";
    }
    // The step's own force on the bone: the new loop with no motion.
    const auto t_capture = Clock::now();
    loop = taut::HapticForceLoop::Capture(scene.world(), scene.bone());
    run.ms_capture.push_back(MsSince(t_capture));
    const taut::HapticWrench now = loop.CalcToolWrench(taut::ToolMotion());
    const double table = ReportedTableForce(scene.world(), scene.table());
    csv << t0 + dt << ",0," << now.force.z() << "," << table << "," << now.sweeps << ","
        << now.microseconds << "\n";
    const bool moved = !(before.getOrigin() == after.getOrigin());
    if (have_loop && moved && std::abs(now.force.z()) > 1.0)
      run.prediction_error.push_back(std::abs(last_tick_force - now.force.z()) /
                                     std::abs(now.force.z()));
    have_loop = true;
    ++run.steps;
    scene.Measure(dt);
  }
  return run;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"taut-haptic: a 1 kHz haptic loop on the finger pressed by its bone"};
  std::string out_dir = "out/haptic";
  double dt = 0.004, rate = 1000.0, target = 40.0, hold = 0.05, speed = 0.005, gap = 2e-4;
  int max_steps = 100000;
  app.add_option("--out", out_dir, "Output folder, created if missing");
  app.add_option("--dt", dt, "Full step [s]")->check(CLI::PositiveNumber);
  app.add_option("--rate", rate, "Haptic rate [Hz]; rate * dt ticks per step")
      ->check(CLI::PositiveNumber);
  app.add_option("--target", target, "Table reaction that stops the bone [N]")
      ->check(CLI::PositiveNumber);
  app.add_option("--speed", speed, "Bone speed while pressing [m/s]")->check(CLI::PositiveNumber);
  app.add_option("--gap", gap, "Lowest node above the table at the start [m]")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--hold", hold, "Time the bone holds at the end [s]")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--steps", max_steps, "At most this many steps")->check(CLI::PositiveNumber);
  CLI11_PARSE(app, argc, argv);
  try {
    std::filesystem::create_directories(out_dir);
    taut::FingerSceneSettings settings;
    settings.target_force = target;
    settings.hold_time = hold;
    settings.bone_speed = speed;
    settings.start_gap = gap;
    taut::FingerScene scene({{taut::FingerPressAxis::kFlat, taut::FingerScene::Anisotropic()}},
                            settings);
    std::ofstream csv(out_dir + "/haptic.csv");
    csv.precision(10);
    csv << "time_s,haptic,bone_force_z_N,table_force_z_N,pgs_sweeps,query_us\n";
    const int ticks = std::max(1, static_cast<int>(std::lround(rate * dt)));
    const HapticRun run = RunPress(scene, dt, ticks, max_steps, csv);
    const double step_ms = Median(run.ms_step), query_us = Median(run.us_query);
    std::printf("taut-haptic: %d steps of %.4g s, %d haptic queries (%d per step)\n", run.steps, dt,
                run.queries, ticks);
    std::printf("  full step %.3f ms, capture %.3f ms, haptic query %.1f us (medians): %.0fx\n",
                step_ms, Median(run.ms_capture), query_us,
                query_us > 0.0 ? 1e3 * step_ms / query_us : 0.0);
    const double worst =
        run.prediction_error.empty()
            ? 0.0
            : *std::max_element(run.prediction_error.begin(), run.prediction_error.end());
    std::printf(
        "  last tick before a step vs that step's bone force, over %zu steps the bone moved in: "
        "median error %.2f %%, largest %.2f %%\n",
        run.prediction_error.size(), 100.0 * Median(run.prediction_error), 100.0 * worst);
    const taut::FingerPressResult& press = scene.result(0);
    std::printf("  press %s: stop '%s' at %.2f N, indentation %.3f mm\n", press.name.c_str(),
                press.stop_reason.c_str(), press.reaction, 1e3 * press.indentation);
    std::printf("  wrote %s/haptic.csv\n", out_dir.c_str());
  } catch (const std::exception& e) {
    std::cerr << "taut-haptic: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
