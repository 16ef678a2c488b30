// The markdown page taut-report writes (docs/report.md): method, then one section per scene with
// its table, its plot and its CSV.
//
// Header-only (inline) on purpose: tests/report_*_test.cc check this logic, and the tool's .cc
// files are linked only into taut-report, not into the test binary.
#pragma once

#include <string>
#include <vector>

#include "demos/tools/report/report_table.h"
#include "demos/tools/report/sweep_plan.h"

namespace taut {

// One scene's part of the page.
struct SceneSection {
  std::string name;
  std::string description;
  std::string skipped;      // non-empty: why the scene was not measured
  double duration_s = 0.0;  // simulated time of every run [s]
  double dt = 0.0;          // scene time step [s]
  std::string reference;    // how the reference run was made
  std::vector<ReportRow> rows;
  std::string csv_link;   // relative to the page
  std::string png_link;   // relative to the page; empty: no plot
  std::string plot_note;  // why there is no plot, or how to redraw it
};

// Facts about the whole run printed above the scenes.
struct ReportHeader {
  std::string command;            // command line that produced the page
  std::string machine;            // CPU model
  std::string build;              // build flavour (optimized or with assertions)
  double wall_s = 0.0;            // wall time of the whole report [s]
  bool has_lcp_residual = false;  // StepStats carries the natural-map residual
  SweepLists lists;
};

// Comma-separated text of a list.
template <typename T>
std::string JoinKnobs(const std::vector<T>& values) {
  std::string text;
  for (const T& v : values) text += (text.empty() ? "" : ", ") + FormatKnob(double(v));
  return text;
}

// The method part of the page (what is swept, what each column means).
inline std::string FormatReportMethod(const ReportHeader& h) {
  std::string s =
      "Every scene of the registry is run once per solver setting for the same simulated time, "
      "each run changing one knob of the default settings (family):\n\n";
  s += "- `pgs`: PGS sweep cap per QP (`pgs.max_sweeps`): " + JoinKnobs(h.lists.pgs_sweeps) + ".\n";
  s += "- `sqp`: SQP iteration cap (`max_iterations`): " + JoinKnobs(h.lists.sqp_iterations) +
       ", at the `tol` family's tightest tolerance so that the cap is what stops the loop.\n";
  s += "- `tol`: SQP tolerances " + JoinKnobs(h.lists.tolerance_factors) +
       " times the scene's (violation, stationarity and contact tolerances alike; the label is "
       "the violation tolerance), iteration cap at its default.\n";
  s += "- `dt`: time step dt / " + JoinKnobs(h.lists.dt_divisors) +
       " with the default solver settings, over the same simulated time.\n";
  const SqpSettings ref = MakeReferenceSettings(SqpSettings{});
  s += "- `reference`: dt / " + std::to_string(h.lists.reference_divisor) +
       " with tight settings (" + std::to_string(ref.max_iterations) +
       " SQP iterations, tolerances " + FormatKnob(kReferenceToleranceFactor) +
       " times the scene's, " + std::to_string(ref.pgs.max_sweeps) + " PGS sweeps at tolerance " +
       FormatKnob(ref.pgs.tolerance) + "); the trajectory error is measured against it.\n\n";
  s += "Columns: `ms/step` is the median wall time of one `Scene::Step`; `ms/frame` the median "
       "wall time of the steps of one 1/60 s frame; `CPU ms/frame` the CPU time of all steps "
       "(one thread) per simulated 1/60 s frame, the x axis of the plots: it puts time steps of "
       "different length on one cost axis, counts the few costly frames of an impact that a "
       "median hides, and does not grow when other processes share the machine (the CSV also "
       "has the wall-time mean, `ms_frame_mean`). "
       "`SQP it.` and `PGS sweeps` are means per "
       "step; `unconv.` counts steps that ended on a cap; `max viol.` is the largest "
       "`violation_after` of a step: max(0, -C) over strain- and energy-limit rows (C is a "
       "fraction of the limit, so 0.01 is 1 % past it; where the solver folds contact and joint "
       "rows in, their depth counts scaled by violation / contact tolerance); `max U/Umax` the "
       "largest element energy ratio of an "
       "energy-limited body (from the scene's figures); `max pen.` the deepest contact "
       "penetration; `max stat.` and `mean stat.` the SQP stationarity "
       "||A(v - v*) - J^T lambda|| / ||J^T lambda|| at the end of a step (max and mean over steps "
       "with rows); `traj. err.` the RMS over the 1/60 s sample times of "
       "sqrt(mean over free nodes of |x - x_ref|^2) / L, L the body's rest bounding-box "
       "diagonal. A dash means the scene or the step statistics do not expose the figure.\n\n";
  if (!h.has_lcp_residual)
    s += "The step statistics do not carry the final LCP (natural-map) residual yet, so the "
         "stationarity stands for solver accuracy.\n\n";
  return s;
}

// The whole page.
inline std::string FormatReportMarkdown(const ReportHeader& h,
                                        const std::vector<SceneSection>& scenes) {
  std::string s = "# Error against run time\n\n";
  s += "Generated by `taut-report` (demos/tools/report); do not edit by hand. Reproduce with "
       "`scripts/run_report.sh`.\n\n";
  char line[512];
  std::snprintf(line, sizeof(line),
                "Command: `%s`; total wall time %.0f s on %s (one thread, %s).\n\n",
                h.command.c_str(), h.wall_s, h.machine.c_str(), h.build.c_str());

  s += line;
  s += FormatReportMethod(h);
  for (const SceneSection& scene : scenes) {
    s += "## " + scene.name + "\n\n" + scene.description + "\n\n";
    if (!scene.skipped.empty()) {
      s += "Not measured: " + scene.skipped + "\n\n";
      continue;
    }
    std::snprintf(line, sizeof(line), "Simulated time %.4g s at dt = %.4g ms; reference: %s.\n\n",
                  scene.duration_s, 1e3 * scene.dt, scene.reference.c_str());
    s += line;
    s += FormatMarkdownTable(scene.rows) + "\n";
    if (!scene.png_link.empty()) s += "![" + scene.name + "](" + scene.png_link + ")\n\n";
    if (!scene.plot_note.empty()) s += scene.plot_note + "\n\n";
    s += "Data: [" + scene.csv_link + "](" + scene.csv_link + ")\n\n";
  }
  return s;
}

}  // namespace taut
