// One scene's part of taut-report: reference run, sweep, CSV, plot and markdown section.
#pragma once

#include <string>

#include "demos/scenes/scene.h"
#include "demos/tools/report/report_markdown.h"
#include "demos/tools/report/sweep_plan.h"

namespace taut {

// How much of each scene taut-report runs.
struct SceneReportOptions {
  SweepLists lists;
  int steps = 0;                   // steps of the scene's dt per run (0: from duration_s)
  double duration_s = 1.0;         // simulated time per run, capped at the scene's default run [s]
  double reference_budget_s = 40;  // CPU time of the reference run; its reach sets the duration [s]
  double run_budget_s = 60;        // CPU time after which a sweep run stops ("timeout") [s]
  std::string out_dir;             // CSV, gnuplot scripts and PNGs
  std::string page_dir;            // folder of the markdown page (links are relative to it)
};

// Runs the reference and every sweep point of one scene, writes <out_dir>/<scene>.csv and its
// plot, and returns the scene's section of the page. A scene that cannot be built (missing data)
// or whose reference fails at once is returned as skipped, with the reason.
SceneSection MeasureScene(const SceneInfo& info, const SceneReportOptions& options);

}  // namespace taut
