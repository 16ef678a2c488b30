// taut-demo: runs one headless scene and writes DIR/summary.json, DIR/steps.csv and, with --vtk,
// VTK frames for ParaView (docs/architecture.md §7).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>

#include "demos/render/picture_recorder.h"
#include "demos/scenes/demo_options.h"
#include "demos/scenes/scene.h"

namespace {

// Median of a copy of the values.
double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

// The island solver path chosen by --solver (kAuto: the world's per-island rule).
taut::IslandSolverKind& SolverChoice() {
  static taut::IslandSolverKind kind = taut::IslandSolverKind::kAuto;
  return kind;
}

// Threads that step the deformables, chosen by --threads (DeformableWorld::SetThreadCount).
int& ThreadCount() {
  static int threads = 1;
  return threads;
}

// The dual path's SQP iteration cap chosen by --sqp-iterations (0: the scene's,
// SqpSettings::max_iterations).
int& SqpIterationCap() {
  static int cap = 0;
  return cap;
}

// --dual-curvature: the dual path's QPs in the metric A + G (SqpSettings::dual_curvature).
bool& DualCurvature() {
  static bool on = false;
  return on;
}

// Runs the scene and writes its outputs; returns the process exit code.
int RunScene(const taut::SceneInfo& info, int steps, double dt, const std::string& out_dir,
             bool vtk, int vtk_every, bool png) {
  namespace fs = std::filesystem;
  fs::create_directories(out_dir);
  std::unique_ptr<taut::Scene> scene = info.make();
  if (SolverChoice() != taut::IslandSolverKind::kAuto)
    scene->mutable_solver_settings().solver = SolverChoice();
  if (SqpIterationCap() > 0) scene->mutable_solver_settings().max_iterations = SqpIterationCap();
  if (DualCurvature()) scene->mutable_solver_settings().dual_curvature = true;
  scene->SetThreadCount(ThreadCount());
  std::ofstream csv(out_dir + "/steps.csv");
  csv.precision(17);
  csv << "step,time_s,ms_step,ms_unconstrained,ms_rows,ms_solve,ms_rigid";
  for (const taut::RowTypeInfo& info : taut::kRowTypes) csv << ",rows_" << info.name;
  csv << ",islands,rigid_bodies_coupled,pgs_sweeps,sqp_iterations,restoration_iterations,"
         "active_set_solves,"
         "violation_before,violation_after,stationarity,converged,islands_dual,islands_primal,"
         "newton_iterations,pcg_iterations,kkt_primal,kkt_complementarity,kkt_dual";
  for (const std::string& column : scene->CsvColumns()) csv << "," << column;
  csv << "\n";
  std::vector<double> ms_steps, values;
  int max_sqp = 0, total_sweeps = 0, unconverged_steps = 0;
  double total_sqp = 0.0;
  double max_violation = 0.0;
  const auto run_start = std::chrono::steady_clock::now();
  auto last_progress = run_start;
  if (vtk) scene->WriteVtkFrame(out_dir, 0, 0.0);
  // Pictures (--png): snapshots are taken between the timed steps and rendered after the run.
  std::unique_ptr<taut::render::PictureRecorder> pictures;
  if (png)
    pictures = std::make_unique<taut::render::PictureRecorder>(out_dir, info.name, steps, dt);
  if (pictures) pictures->Record(*scene, 0);
  for (int step = 1; step <= steps; ++step) {
    // Only the simulation is timed; the scene's own measurements follow the timer.
    const auto t0 = std::chrono::steady_clock::now();
    scene->Simulate(dt);
    const auto t1 = std::chrono::steady_clock::now();
    scene->Measure(dt);
    const double ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
    ms_steps.push_back(ms);
    const taut::StepStats& s = scene->last_step_stats();
    max_sqp = std::max(max_sqp, s.sqp_iterations);
    total_sqp += s.sqp_iterations;
    unconverged_steps += s.converged ? 0 : 1;
    total_sweeps += s.pgs_sweeps;
    max_violation = std::max(max_violation, s.violation_after);
    csv << step << "," << step * dt << "," << ms << "," << s.ms_unconstrained << "," << s.ms_rows
        << "," << s.ms_solve << "," << s.ms_rigid;
    for (const taut::RowTypeInfo& info : taut::kRowTypes) csv << "," << s.rows_of(info.type);
    csv << "," << s.islands << "," << s.rigid_bodies_coupled << "," << s.pgs_sweeps << ","
        << s.sqp_iterations << "," << s.restoration_iterations << "," << s.active_set_solves << ","
        << s.violation_before << "," << s.violation_after << "," << s.stationarity << ","
        << (s.converged ? 1 : 0) << "," << s.islands_dual << "," << s.islands_primal << ","
        << s.newton_iterations << "," << s.pcg_iterations << "," << s.kkt_primal << ","
        << s.kkt_complementarity << "," << s.kkt_dual;
    values.clear();
    scene->AppendCsvValues(values);
    for (double v : values) csv << "," << v;
    csv << "\n";
    if (vtk && step % vtk_every == 0) scene->WriteVtkFrame(out_dir, step / vtk_every, step * dt);
    if (pictures) pictures->Record(*scene, step);
    if (std::chrono::duration<double>(t1 - last_progress).count() > 2.0 || step == steps) {
      std::fprintf(stderr, "\r%s: step %d/%d (%.0f%%), %.3f ms/step", info.name.c_str(), step,
                   steps, 100.0 * step / steps, Median(ms_steps));
      last_progress = t1;
    }
  }
  std::fprintf(stderr, "\n");
  nlohmann::json summary;
  summary["scene"] = info.name;
  summary["description"] = info.description;
  summary["steps"] = steps;
  summary["dt"] = dt;
  summary["ms_per_step_median"] = Median(ms_steps);
  // A 1/60 s display frame takes (1/60) / dt steps.
  summary["ms_per_frame_60hz"] = Median(ms_steps) / (60.0 * dt);
  summary["wall_time_s"] =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - run_start).count();
  summary["max_violation"] = max_violation;
  summary["max_sqp_iterations"] = max_sqp;
  summary["mean_sqp_iterations"] = steps > 0 ? total_sqp / steps : 0.0;
  summary["unconverged_steps"] = unconverged_steps;
  summary["pgs_sweeps_total"] = total_sweeps;
  summary["pgs_sweeps_per_step_mean"] = steps > 0 ? static_cast<double>(total_sweeps) / steps : 0.0;
  char hash[32];
  std::snprintf(hash, sizeof(hash), "%016llx",
                static_cast<unsigned long long>(scene->CalcStateHash()));
  summary["state_hash"] = hash;
  nlohmann::json figures;
  scene->WriteFigures(figures);
  summary["figures"] = figures;
  if (pictures) {
    const taut::render::PictureReport report = pictures->Finish(scene->GetCameraDirection());
    nlohmann::json& entry = summary["pictures"];
    entry["key_frames"] = report.key_frames;
    entry["gif_frames"] = report.gif_frames;
    entry["ms_capture_total"] = report.ms_capture;
    entry["ms_render_key_frame"] = report.ms_render_frame;
    entry["ms_render_gif_frame"] = report.ms_render_gif_frame;
    entry["ms_write_png"] = report.ms_write_png;
    entry["ms_write_gif_total"] = report.ms_write_gif;
    for (const std::string& file : report.files)
      entry["files"].push_back(std::filesystem::path(file).filename().string());
  }
  std::ofstream(out_dir + "/summary.json") << summary.dump(2) << "\n";
  std::cout << taut::FormatRunReport(summary, out_dir) << std::flush;
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"taut-demo: headless scenes of limited-elasticity deformable bodies in Bullet"};
  bool list = false, vtk = false, png = false;
  std::string scene_name, out_dir;
  int steps = 0, vtk_every = 1;
  double dt = 0.0;
  app.add_flag("--list", list, "List the scenes, one per line, and exit");
  app.add_option("scene", scene_name, "Scene to run (see the list below or --list)");
  // Positive values are checked by taut::ResolveDemoArguments (one-line errors).
  CLI::Option* steps_option =
      app.add_option("--steps", steps, "Number of steps, > 0 (default: the scene's)");
  CLI::Option* dt_option =
      app.add_option("--dt", dt, "Time step in seconds, > 0 (default: the scene's)");
  app.add_option("--out", out_dir, "Output folder, created if missing (default: out/<scene>)");
  app.footer("Scenes:\n" + taut::FormatSceneList());
  app.add_flag("--vtk", vtk, "Write VTK frames of every deformable body");
  app.add_option("--vtk-every", vtk_every, "Write a VTK frame every N steps")
      ->check(CLI::PositiveNumber);
  app.add_flag("--png", png,
               "Write pictures: the scene's key frames (key_*.png), figure.png and run.gif");
  const std::map<std::string, taut::IslandSolverKind> solvers = {
      {"auto", taut::IslandSolverKind::kAuto},
      {"dual", taut::IslandSolverKind::kDual},
      {"primal", taut::IslandSolverKind::kPrimal}};
  app.add_option("--solver", SolverChoice(),
                 "Island solver: auto (per island by rows per DOF), dual (the papers' PGS) or "
                 "primal (augmented-Lagrangian Newton)")
      ->transform(CLI::CheckedTransformer(solvers, CLI::ignore_case));
  app.add_option("--sqp-iterations", SqpIterationCap(),
                 "SQP iteration cap of the dual path, >= 1 (default: the scene's, usually 10)")
      ->check(CLI::PositiveNumber);
  app.add_flag("--dual-curvature", DualCurvature(),
               "Dual path: each QP in the metric A + G, G the limit rows' curvature (default: the "
               "papers' metric A)");
  app.add_option("--threads", ThreadCount(),
                 "Threads stepping the bodies and independent islands, >= 1 (default 1; results "
                 "are the same for any count)")
      ->check(CLI::PositiveNumber);
  CLI11_PARSE(app, argc, argv);
  try {
    if (list) {
      for (const taut::SceneInfo& info : taut::SceneRegistry())
        std::cout << info.name << "  # " << info.description << "\n";
      return 0;
    }
    taut::DemoArguments args;
    args.scene = scene_name;
    if (steps_option->count() > 0) args.steps = steps;
    if (dt_option->count() > 0) args.dt = dt;
    args.out_dir = out_dir;
    taut::DemoRun run;
    try {
      run = taut::ResolveDemoArguments(args);
    } catch (const taut::InputError& e) {
      std::cerr << "taut-demo: " << e.what() << "\n";
      return 2;
    }
    return RunScene(*run.scene, run.steps, run.dt, run.out_dir, vtk, vtk_every, png);
  } catch (const std::exception& e) {
    std::cerr << "taut-demo: " << e.what() << "\n";
    return 1;
  }
}
