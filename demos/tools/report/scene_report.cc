#include "demos/tools/report/scene_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>

#include "demos/tools/report/report_files.h"
#include "demos/tools/report/scene_run.h"

namespace taut {

namespace {

// Prints one finished run to stderr.
void LogRun(const std::string& scene, const ReportRow& row) {
  std::fprintf(
      stderr,
      "  %-15s %-9s %-7s %-6s %9.3f CPU ms/frame  unconv %-4d viol %-9.3g stat %-9.3g err %-9.3g "
      "%7.1f s  %s\n",
      scene.c_str(), row.family.c_str(), row.label.c_str(), row.solver.c_str(),
      row.cpu_ms_frame_mean, row.unconverged_steps, row.max_violation, row.max_stationarity,
      row.traj_error_rms, row.wall_s, row.status.c_str());
}

// Path of `path` relative to folder `base` (both as given, made absolute first).
std::string RelativeTo(const std::string& path, const std::string& base) {
  namespace fs = std::filesystem;
  return fs::absolute(path)
      .lexically_normal()
      .lexically_relative(fs::absolute(base).lexically_normal())
      .generic_string();
}

}  // namespace

SceneSection MeasureScene(const SceneInfo& info, const SceneReportOptions& options) {
  SceneSection section;
  section.name = info.name;
  section.description = info.description;
  section.dt = info.default_dt;
  // Default settings from one throw-away build.
  SqpSettings base;
  try {
    base = info.make()->world().solver_settings();
  } catch (const std::exception& e) {
    section.skipped = e.what();
    std::fprintf(stderr, "%s: skipped (%s)\n", info.name.c_str(), e.what());
    return section;
  }
  // Run length in whole sample intervals of about one 1/60 s frame.
  RunPlan plan;
  plan.dt = info.default_dt;
  const double scene_time = info.default_steps * info.default_dt;
  const int steps = options.steps > 0
                        ? options.steps
                        : std::max(1, static_cast<int>(std::lround(
                                          std::min(options.duration_s, scene_time) / plan.dt)));
  plan.frame_steps = std::clamp(static_cast<int>(std::lround(1.0 / 60.0 / plan.dt)), 1, steps);
  plan.samples = std::max(1, steps / plan.frame_steps);
  // Reference first: where it gets within its budget sets the simulated time of every run.
  const int divisor = options.lists.reference_divisor;
  const SweepPoint reference_point{"reference", "dt/" + std::to_string(divisor), divisor,
                                   MakeReferenceSettings(base, options.lists.reference_solver)};
  plan.cpu_budget_s = options.reference_budget_s;
  RunOutcome reference_run = RunSweepPoint(info, reference_point, plan, nullptr);
  LogRun(info.name, reference_run.row);
  if (reference_run.completed_samples == 0) {
    section.skipped = "the reference run " + reference_run.row.status;
    return section;
  }
  std::string cut;
  if (reference_run.row.status.rfind("timeout", 0) == 0)
    cut = internal::Concat(" (stopped by its ", options.reference_budget_s, " s CPU budget)");
  else if (reference_run.row.status != "ok")
    cut = " (" + reference_run.row.status + ")";
  plan.samples = reference_run.completed_samples;
  section.duration_s = plan.samples * plan.frame_steps * plan.dt;
  char text[256];
  std::snprintf(text, sizeof(text),
                "dt/%d with tight settings on the %s path, %d of %d steps uncertified, %.1f s "
                "wall%s",
                divisor, reference_run.row.solver.c_str(), reference_run.row.unconverged_steps,
                reference_run.row.steps, reference_run.row.wall_s, cut.c_str());
  section.reference = text;
  ReferenceTrajectory reference{reference_run.samples, reference_run.lengths};
  reference.samples.resize(plan.samples);
  reference.lengths.resize(plan.samples);
  reference_run.row.status = "reference";
  reference_run.row.traj_error_rms = reference_run.row.traj_error_end = 0.0;
  // The sweep; points that would run identically share one run.
  plan.cpu_budget_s = options.run_budget_s;
  const std::vector<SweepPoint> points = MakeSweepPlan(options.lists, base);
  std::map<std::string, ReportRow> done;
  for (const SweepPoint& point : points) {
    const std::string key = CalcRunKey(point);
    auto it = done.find(key);
    if (it == done.end()) {
      it = done.emplace(key, RunSweepPoint(info, point, plan, &reference).row).first;
      LogRun(info.name, it->second);
    }
    ReportRow row = it->second;
    row.family = point.family;
    row.label = point.label;
    section.rows.push_back(row);
  }
  section.rows.push_back(reference_run.row);
  // Files.
  std::filesystem::create_directories(options.out_dir);
  const std::string csv = options.out_dir + "/" + info.name + ".csv";
  WriteReportCsv(csv, section.rows);
  section.csv_link = RelativeTo(csv, options.page_dir);
  const PlotFiles plot =
      WriteReportPlot(options.out_dir, info.name, section.rows, ListCurves(points));
  if (!plot.png.empty()) section.png_link = RelativeTo(plot.png, options.page_dir);
  section.plot_note = plot.note;
  return section;
}

}  // namespace taut
