// The markdown page taut-report writes (docs/report.md): method, then one section per scene with
// its table, its plot and its CSV.
//
// Header-only (inline) on purpose: tests/report_*_test.cc check this logic, and the tool's .cc
// files are linked only into taut-report, not into the test binary.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
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
  std::string sweep_note;         // non-empty: why the sweep is coarser than the default
  SweepLists lists;
};

// Comma-separated text of a list.
template <typename T>
std::string JoinKnobs(const std::vector<T>& values) {
  std::string text;
  for (const T& v : values) text += (text.empty() ? "" : ", ") + FormatKnob(double(v));
  return text;
}

// Names of solver kinds, comma-separated.
inline std::string JoinSolvers(const std::vector<IslandSolverKind>& kinds) {
  std::string text;
  for (IslandSolverKind k : kinds)
    text += (text.empty() ? "" : ", ") + std::string(GetIslandSolverName(k));
  return text;
}

// The method part of the page (what is swept, what each column means).
inline std::string FormatReportMethod(const ReportHeader& h) {
  std::string s =
      "Every scene of the registry is run once per solver setting for the same simulated time, "
      "each run changing one knob of the default settings (family), and every family is run on "
      "each island solver path (`solver` column: " +
      JoinSolvers(h.lists.solvers) +
      "; `SqpSettings::solver`): `dual` is the papers' PGS per QP inside the SQP, `primal` the "
      "augmented-Lagrangian Newton path, `auto` picks per island and step by rows per free DOF "
      "and after a failed dual step.\n\n";
  s += "- `default`: the scene's default settings on each path" +
       std::string(h.lists.auto_default ? ", `auto` included" : "") + " (label: the path).\n";
  s += "- `pgs`: PGS sweep cap per QP (`pgs.max_sweeps`): " + JoinKnobs(h.lists.pgs_sweeps) +
       "; dual path only, since the primal path runs no PGS.\n";
  s +=
      "- `newton`: Newton iteration cap per linearized problem (`primal.max_newton_iterations`): " +
      JoinKnobs(h.lists.newton_iterations) + "; primal path only (its stand-in for the PGS cap).\n";
  if (!h.lists.penalty_scales.empty())
    s += "- `penalty`: penalty over each row's compliance (`primal.penalty_scale`): " +
         JoinKnobs(h.lists.penalty_scales) + "; primal path only.\n";
  s += "- `sqp`: SQP iteration cap (`max_iterations`, and `primal.max_iterations` on the primal "
       "path): " +
       JoinKnobs(h.lists.sqp_iterations) +
       ", at the `tol` family's tightest tolerance so that the cap is what stops the loop.\n";
  s += "- `tol`: SQP tolerances " + JoinKnobs(h.lists.tolerance_factors) +
       " times the scene's (violation, stationarity and contact tolerances alike; the label is "
       "the violation tolerance), iteration caps at their defaults.\n";
  s += "- `dt`: time step dt / " + JoinKnobs(h.lists.dt_divisors) +
       " with the default solver settings, over the same simulated time.\n";
  const SqpSettings ref = MakeReferenceSettings(SqpSettings{}, h.lists.reference_solver);
  s += "- `reference`: dt / " + std::to_string(h.lists.reference_divisor) + " on the " +
       GetIslandSolverName(h.lists.reference_solver) + " path with tight settings (tolerances " +
       FormatKnob(kReferenceToleranceFactor) + " times the scene's, " +
       std::to_string(ref.primal.max_iterations) + " primal SQP iterations of up to " +
       std::to_string(ref.primal.max_newton_iterations) + " Newton steps; on the dual path " +
       std::to_string(ref.max_iterations) + " SQP iterations, " +
       std::to_string(ref.pgs.max_sweeps) + " PGS sweeps at tolerance " +
       FormatKnob(ref.pgs.tolerance) +
       "); the trajectory error of both paths is measured against this one reference.\n\n";
  s += "Columns: `ms/step` is the median wall time of one `Scene::Step`; `ms/frame` the median "
       "wall time of the steps of one 1/60 s frame; `CPU ms/frame` the CPU time of all steps "
       "(one thread) per simulated 1/60 s frame, the x axis of the plots: it puts time steps of "
       "different length on one cost axis, counts the few costly frames of an impact that a "
       "median hides, and does not grow when other processes share the machine (the CSV also "
       "has the wall-time mean, `ms_frame_mean`). "
       "`SQP it.`, `PGS sweeps` and `Newton it.` are means per "
       "step (PGS: dual path, Newton: primal path); `primal share` the fraction of island solves "
       "that took the primal path; `unconv.` counts steps whose KKT certificate failed "
       "(`StepStats::converged`: primal, complementarity, dual and stationarity residuals all "
       "within tolerance); `max viol.` is the largest "
       "`violation_after` of a step: max(0, -C) over strain- and energy-limit rows (C is a "
       "fraction of the limit, so 0.01 is 1 % past it; where the solver folds contact and joint "
       "rows in, their depth counts scaled by violation / contact tolerance); `max U/Umax` the "
       "largest element energy ratio of an "
       "energy-limited body (from the scene's figures); `max pen.` the deepest contact "
       "penetration; `KKT primal`, `KKT compl.` and `KKT dual` the largest certificate residuals "
       "of a "
       "step (`kkt_primal`: max(0, -C) of every row, `kkt_complementarity`: |C| of pushing rows "
       "and slip of sticking contacts, both in C units; `kkt_dual`: distance of lambda from its "
       "set relative to max |lambda|); `max LCP res.` the natural-map residual of the dual path's "
       "last QP; `max stat.` and `mean stat.` the SQP stationarity "
       "||A(v - v*) - J^T lambda|| / max(||J^T lambda||, ||A(v - v*)||) at the end of a step (max "
       "and mean over steps "
       "with rows); `traj. err.` the RMS over the 1/60 s sample times of "
       "sqrt(mean over free nodes of |x - x_ref|^2) / L, L the body's rest bounding-box "
       "diagonal. A dash means the scene or the step statistics do not expose the figure. "
       "A run that failed (a body left the simulation) stays in the table with the reason but is "
       "not drawn: its figures cover only the steps before the failure; a run stopped by its CPU "
       "budget (timeout) is drawn, its figures covering the time it reached.\n\n";
  if (!h.has_lcp_residual)
    s += "The step statistics do not carry the final LCP (natural-map) residual yet, so the "
         "stationarity stands for solver accuracy.\n\n";
  return s;
}

// The row of `scene` in `family` on path `solver`, or nullptr.
inline const ReportRow* FindRow(const SceneSection& scene, const std::string& family,
                                const std::string& solver) {
  for (const ReportRow& r : scene.rows)
    if (r.family == family && r.solver == solver) return &r;
  return nullptr;
}

// The finished sweep row of path `solver` with the smallest trajectory error, or nullptr.
inline const ReportRow* FindMostAccurateRow(const SceneSection& scene, const std::string& solver) {
  const ReportRow* best = nullptr;
  for (const ReportRow& r : scene.rows)
    if (r.family != "reference" && r.solver == solver && r.status == "ok" &&
        std::isfinite(r.traj_error_rms) &&
        (best == nullptr || r.traj_error_rms < best->traj_error_rms))
      best = &r;
  return best;
}

// Which of a (dual) and b (primal) is smaller: "dual", "primal", "tie" (within 10 %) or "?".
inline std::string NameSmaller(double a, double b) {
  if (!std::isfinite(a) || !std::isfinite(b)) return "?";
  if (std::abs(a - b) <= 0.1 * std::max(a, b)) return "tie";
  return a < b ? "dual" : "primal";
}

// Verdict text of NameSmaller: "**primal**", "tie (within 10 %)", "undecided (a figure is
// missing)".
inline std::string FormatVerdict(const std::string& winner) {
  if (winner == "tie") return "tie (within 10 %)";
  if (winner == "?") return "undecided (a figure is missing)";
  return "**" + winner + "**";
}

// The summary above the method: per scene the default-settings run of each path (uncertified
// steps, max violation, cost, trajectory error), the most accurate run of each path in the sweep,
// and which path is better by error (trajectory error, then uncertified steps) and by time (CPU
// time per frame).
inline std::string FormatSolverSummary(const std::vector<SceneSection>& scenes) {
  std::string s = "## Summary: dual against primal\n\n";
  std::string table =
      "| scene | solver | unconv. | max viol. | ms/step | CPU ms/frame | traj. err. | best traj. "
      "err. in the sweep (setting, CPU ms/frame) |\n| --- | --- | ---: | ---: | ---: | ---: | ---: "
      "| --- |\n";
  std::string verdicts;
  bool any_row = false;
  char text[512];
  for (const SceneSection& scene : scenes) {
    if (!scene.skipped.empty() || scene.rows.empty()) continue;
    for (const char* solver : {"dual", "primal", "auto"}) {
      const ReportRow* r = FindRow(scene, "default", solver);
      if (r == nullptr) continue;
      const ReportRow* best = FindMostAccurateRow(scene, solver);
      std::string best_text = "–";
      if (best != nullptr && std::string(solver) != "auto")
        best_text = FormatFigure(best->traj_error_rms, false) + " (" + best->family + " " +
                    best->label + ", " + FormatFigure(best->cpu_ms_frame_mean, false) + ")";
      any_row = true;
      std::string status = r->status == "ok" ? "" : " (" + r->status + ")";
      table += "| " + scene.name + " | " + solver + status + " | " +
               FormatFigure(r->unconverged_steps, true) + " of " + FormatFigure(r->steps, true) +
               " | " + FormatFigure(r->max_violation, false) + " | " +
               FormatFigure(r->ms_step, false) + " | " + FormatFigure(r->cpu_ms_frame_mean, false) +
               " | " + FormatFigure(r->traj_error_rms, false) + " | " + best_text + " |\n";
    }
    const ReportRow* d = FindRow(scene, "default", "dual");
    const ReportRow* p = FindRow(scene, "default", "primal");
    if (d == nullptr || p == nullptr) continue;
    std::string by_error = NameSmaller(d->traj_error_rms, p->traj_error_rms);
    if (by_error == "tie" && d->unconverged_steps != p->unconverged_steps)
      by_error = d->unconverged_steps < p->unconverged_steps ? "dual" : "primal";
    const std::string by_time = NameSmaller(d->cpu_ms_frame_mean, p->cpu_ms_frame_mean);
    std::snprintf(text, sizeof(text),
                  "- **%s**: error: %s, traj. err. %s (dual) vs %s (primal), uncertified steps %d "
                  "vs %d, max viol. %s vs %s; time: %s, CPU ms/frame %s vs %s (primal/dual "
                  "%s).\n",
                  scene.name.c_str(), FormatVerdict(by_error).c_str(),
                  FormatFigure(d->traj_error_rms, false).c_str(),
                  FormatFigure(p->traj_error_rms, false).c_str(), d->unconverged_steps,
                  p->unconverged_steps, FormatFigure(d->max_violation, false).c_str(),
                  FormatFigure(p->max_violation, false).c_str(), FormatVerdict(by_time).c_str(),
                  FormatFigure(d->cpu_ms_frame_mean, false).c_str(),
                  FormatFigure(p->cpu_ms_frame_mean, false).c_str(),
                  FormatFigure(p->cpu_ms_frame_mean / d->cpu_ms_frame_mean, false).c_str());
    verdicts += text;
  }
  if (!any_row) return "";
  s += "Default settings of each scene on each path; the trajectory error is against the "
       "scene's one reference run, cost ratios are within this run (same machine, same load). "
       "The better path is the one smaller by more than 10 % (the timing noise of a shared "
       "machine); for error the uncertified steps break a tie of the trajectory error. The "
       "table adds the `auto` path and the most accurate finished run of each path anywhere in "
       "the sweep.\n\n";
  s += verdicts + "\n" + table + "\n";
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
  if (!h.sweep_note.empty()) s += h.sweep_note + "\n\n";
  s += FormatSolverSummary(scenes);
  s += "## Method\n\n";
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
