// One row of taut-report's results (one sweep point of one scene) and its CSV and markdown forms.
//
// Header-only (inline) on purpose: tests/report_*_test.cc check this logic, and the tool's .cc
// files are linked only into taut-report, not into the test binary.
#pragma once

#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "plugin/common.h"

namespace taut {

// What one run of a scene at one sweep point measured. NaN marks a figure the scene or the
// step statistics do not expose.
struct ReportRow {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  std::string family;  // sweep family ("default", "pgs", "newton", "penalty", "sqp", "tol", "dt",
                       // "reference")
  std::string label;   // value of the family's knob
  std::string solver;  // island solver path of the run: "dual", "primal" or "auto"
  double dt = kNaN;    // time step [s]
  int steps = 0;       // steps run
  int pgs_max_sweeps = 0;
  int sqp_max_iterations = 0;     // dual path's SQP cap
  int primal_max_iterations = 0;  // primal path's SQP (multiplier) cap
  int newton_max_iterations = 0;  // primal path's Newton cap per linearized problem
  double penalty_scale = kNaN;    // primal path's penalty over the row's compliance
  double violation_tolerance = kNaN;
  double stationarity_tolerance = kNaN;
  double ms_step = kNaN;            // median wall time of one step [ms]
  double ms_frame = kNaN;           // median wall time of the steps of one 1/60 s frame [ms]
  double ms_frame_mean = kNaN;      // wall time of all steps per simulated 1/60 s frame [ms]
  double cpu_ms_frame_mean = kNaN;  // the same in CPU time of the stepping thread [ms]
  double wall_s = kNaN;             // wall time of the whole run [s]
  double mean_sqp_iterations = kNaN;
  double mean_pgs_sweeps = kNaN;
  double mean_newton_iterations = kNaN;  // primal path, per step
  double mean_pcg_iterations = kNaN;     // primal path, per step
  double primal_island_share = kNaN;     // island solves on the primal path / all island solves
  int unconverged_steps = 0;       // steps whose KKT certificate failed (StepStats::converged)
  double max_violation = kNaN;     // max over steps of max(0, -C), C units
  double max_energy_ratio = kNaN;  // max U_e/U_max from the scene's figures
  double max_penetration = kNaN;   // deepest contact penetration [m]
  double max_lcp_residual = kNaN;  // max natural-map residual of the last QP of a step
  double max_kkt_primal = kNaN;    // max over steps of the certificate's primal residual
  double max_kkt_complementarity = kNaN;  // ... its complementarity residual (C units)
  double max_kkt_dual = kNaN;             // ... its dual residual (relative to max |lambda|)
  double max_stationarity = kNaN;         // max over steps of the SQP stationarity
  double mean_stationarity = kNaN;        // mean over steps
  double traj_error_rms = kNaN;           // RMS over sample times of the normalized distance
  double traj_error_end = kNaN;           // normalized distance at the last sample time
  std::string status = "ok";              // "ok", "reference", "timeout ...", "failed: ..."
};

// A named numeric column of ReportRow.
struct ReportColumn {
  const char* name;     // CSV header
  const char* heading;  // markdown heading
  std::function<double(const ReportRow&)> get;
  bool integer;  // printed without decimals
};

// 1-based CSV column of the first numeric column (after family, label and solver).
constexpr int kFirstNumericCsvColumn = 4;

// The numeric columns, in CSV order (after family, label and solver, before status).
inline const std::vector<ReportColumn>& ReportColumns() {
  static const std::vector<ReportColumn> columns = {
      {"dt_s", "dt [ms]", [](const ReportRow& r) { return r.dt; }, false},
      {"steps", "steps", [](const ReportRow& r) { return double(r.steps); }, true},
      {"pgs_max_sweeps", "PGS cap", [](const ReportRow& r) { return double(r.pgs_max_sweeps); },
       true},
      {"sqp_max_iterations", "SQP cap",
       [](const ReportRow& r) { return double(r.sqp_max_iterations); }, true},
      {"primal_max_iterations", "primal SQP cap",
       [](const ReportRow& r) { return double(r.primal_max_iterations); }, true},
      {"newton_max_iterations", "Newton cap",
       [](const ReportRow& r) { return double(r.newton_max_iterations); }, true},
      {"penalty_scale", "penalty", [](const ReportRow& r) { return r.penalty_scale; }, false},
      {"violation_tolerance", "viol. tol.",
       [](const ReportRow& r) { return r.violation_tolerance; }, false},
      {"stationarity_tolerance", "stat. tol.",
       [](const ReportRow& r) { return r.stationarity_tolerance; }, false},
      {"ms_step", "ms/step", [](const ReportRow& r) { return r.ms_step; }, false},
      {"ms_frame", "ms/frame", [](const ReportRow& r) { return r.ms_frame; }, false},
      {"ms_frame_mean", "ms/frame (mean)", [](const ReportRow& r) { return r.ms_frame_mean; },
       false},
      {"cpu_ms_frame_mean", "CPU ms/frame", [](const ReportRow& r) { return r.cpu_ms_frame_mean; },
       false},
      {"wall_s", "wall [s]", [](const ReportRow& r) { return r.wall_s; }, false},
      {"mean_sqp_iterations", "SQP it.", [](const ReportRow& r) { return r.mean_sqp_iterations; },
       false},
      {"mean_pgs_sweeps", "PGS sweeps", [](const ReportRow& r) { return r.mean_pgs_sweeps; },
       false},
      {"mean_newton_iterations", "Newton it.",
       [](const ReportRow& r) { return r.mean_newton_iterations; }, false},
      {"mean_pcg_iterations", "PCG it.", [](const ReportRow& r) { return r.mean_pcg_iterations; },
       false},
      {"primal_island_share", "primal share",
       [](const ReportRow& r) { return r.primal_island_share; }, false},
      {"unconverged_steps", "unconv.",
       [](const ReportRow& r) { return double(r.unconverged_steps); }, true},
      {"max_violation", "max viol.", [](const ReportRow& r) { return r.max_violation; }, false},
      {"max_energy_ratio", "max U/Umax", [](const ReportRow& r) { return r.max_energy_ratio; },
       false},
      {"max_penetration_m", "max pen. [mm]", [](const ReportRow& r) { return r.max_penetration; },
       false},
      {"max_lcp_residual", "max LCP res.", [](const ReportRow& r) { return r.max_lcp_residual; },
       false},
      {"max_kkt_primal", "KKT primal", [](const ReportRow& r) { return r.max_kkt_primal; }, false},
      {"max_kkt_complementarity", "KKT compl.",
       [](const ReportRow& r) { return r.max_kkt_complementarity; }, false},
      {"max_kkt_dual", "KKT dual", [](const ReportRow& r) { return r.max_kkt_dual; }, false},
      {"max_stationarity", "max stat.", [](const ReportRow& r) { return r.max_stationarity; },
       false},
      {"mean_stationarity", "mean stat.", [](const ReportRow& r) { return r.mean_stationarity; },
       false},
      {"traj_error_rms", "traj. err. (RMS)", [](const ReportRow& r) { return r.traj_error_rms; },
       false},
      {"traj_error_end", "traj. err. (end)", [](const ReportRow& r) { return r.traj_error_end; },
       false},
  };
  return columns;
}

// 1-based CSV column of `name` (family = 1, label = 2, solver = 3, numeric columns, status
// last); throws InputError for an unknown name.
inline int FindCsvColumn(const std::string& name) {
  if (name == "family") return 1;
  if (name == "label") return 2;
  if (name == "solver") return 3;
  const std::vector<ReportColumn>& columns = ReportColumns();
  for (size_t i = 0; i < columns.size(); ++i)
    if (name == columns[i].name) return static_cast<int>(i) + kFirstNumericCsvColumn;
  if (name == "status") return static_cast<int>(columns.size()) + kFirstNumericCsvColumn;
  throw InputError("report CSV has no column '" + name + "'");
}

// The numeric column `name`; throws InputError for an unknown or non-numeric name.
inline const ReportColumn& FindReportColumn(const std::string& name) {
  const int at = FindCsvColumn(name) - kFirstNumericCsvColumn;
  TAUT_DEMAND(at >= 0 && at < static_cast<int>(ReportColumns().size()), "report column '", name,
              "' is not numeric");
  return ReportColumns()[at];
}

// The CSV header line (no newline).
inline std::string FormatCsvHeader() {
  std::string line = "family,label,solver";
  for (const ReportColumn& c : ReportColumns()) line += std::string(",") + c.name;
  return line + ",status";
}

// Text of a CSV field: commas and line breaks become spaces.
inline std::string SanitizeCsvField(std::string text) {
  for (char& c : text)
    if (c == ',' || c == '\n' || c == '\r') c = ' ';
  return text;
}

// One CSV line of a row (no newline); missing figures are "nan", numbers keep 9 digits.
inline std::string FormatCsvRow(const ReportRow& row) {
  std::string line = SanitizeCsvField(row.family) + "," + SanitizeCsvField(row.label) + "," +
                     SanitizeCsvField(row.solver);
  for (const ReportColumn& c : ReportColumns()) {
    const double v = c.get(row) + 0.0;  // -0 -> 0
    char text[40];
    if (std::isnan(v))
      std::snprintf(text, sizeof(text), "nan");
    else if (c.integer)
      std::snprintf(text, sizeof(text), "%.0f", v);
    else
      std::snprintf(text, sizeof(text), "%.9g", v);
    line += std::string(",") + text;
  }
  return line + "," + SanitizeCsvField(row.status);
}

// Markdown text of a figure: 3 significant digits, "–" when missing.
inline std::string FormatFigure(double value, bool integer) {
  if (std::isnan(value)) return "–";
  char text[40];
  std::snprintf(text, sizeof(text), integer ? "%.0f" : "%.3g", value + 0.0);  // -0 -> 0
  return text;
}

// Markdown table of rows: family, setting and solver, cost, work and every error column. Columns
// that are missing (NaN) in every row are left out; dt and penetration are shown in ms and mm,
// U/Umax with 4 decimals.
inline std::string FormatMarkdownTable(const std::vector<ReportRow>& rows) {
  static const char* kShown[] = {"dt_s",
                                 "ms_step",
                                 "cpu_ms_frame_mean",
                                 "mean_sqp_iterations",
                                 "mean_pgs_sweeps",
                                 "mean_newton_iterations",
                                 "primal_island_share",
                                 "unconverged_steps",
                                 "max_violation",
                                 "max_energy_ratio",
                                 "max_penetration_m",
                                 "max_lcp_residual",
                                 "max_kkt_primal",
                                 "max_kkt_complementarity",
                                 "max_kkt_dual",
                                 "max_stationarity",
                                 "mean_stationarity",
                                 "traj_error_rms"};
  std::vector<const ReportColumn*> shown;
  for (const char* name : kShown) {
    const ReportColumn& c = FindReportColumn(name);
    bool any = false;
    for (const ReportRow& r : rows) any = any || !std::isnan(c.get(r));
    if (any) shown.push_back(&c);
  }
  std::string table = "| family | setting | solver |", rule = "| --- | --- | --- |";
  for (const ReportColumn* c : shown) {
    table += std::string(" ") + c->heading + " |";
    rule += " ---: |";
  }
  table += "\n" + rule + "\n";
  for (const ReportRow& r : rows) {
    std::string label = r.label;
    if (r.status != "ok" && r.status != "reference") label += " (" + r.status + ")";
    table += "| " + r.family + " | " + label + " | " + r.solver + " |";
    for (const ReportColumn* c : shown) {
      double v = c->get(r);
      const std::string name = c->name;
      if (name == "dt_s" || name == "max_penetration_m") v *= 1e3;  // s -> ms, m -> mm
      std::string text = FormatFigure(v, c->integer);
      if (name == "max_energy_ratio" && !std::isnan(v)) {
        char ratio[40];  // 4 decimals: the overshoot over 1 is what matters
        std::snprintf(ratio, sizeof(ratio), "%.4f", v);
        text = ratio;
      }
      table += " " + text + " |";
    }
    table += "\n";
  }
  return table;
}

}  // namespace taut
