// Gnuplot script of taut-report's log-log plots: each error against CPU time per frame, one
// line per sweep family and solver path (colour: family, dash and point: path), read straight
// from the scene's CSV.
//
// Header-only (inline) on purpose: tests/report_*_test.cc check this logic, and the tool's .cc
// files are linked only into taut-report, not into the test binary.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "demos/tools/report/report_table.h"
#include "demos/tools/report/sweep_plan.h"

namespace taut {

// One panel of the plot: CSV column `column` minus `offset` on a log y axis.
struct PlotPanel {
  std::string column;  // CSV column (report_table.h)
  double offset;       // subtracted before plotting (1 for U/Umax: the overshoot)
  std::string ylabel;
};

// What MakeGnuplotScript draws.
struct PlotRequest {
  std::string csv_path;  // the scene's CSV, as gnuplot will open it
  std::string png_path;  // output image
  std::string title;
  std::vector<SweepCurve> curves;  // one line per (family, solver); reference rows never drawn
  std::vector<PlotPanel> panels;
  std::string x_column = "cpu_ms_frame_mean";
};

// Every error taut-report can plot.
inline std::vector<PlotPanel> CandidatePanels() {
  return {{"max_violation", 0.0, "max violation max(0,-C)"},
          {"max_energy_ratio", 1.0, "max U_e/U_max - 1"},
          {"max_penetration_m", 0.0, "max penetration [m]"},
          {"max_lcp_residual", 0.0, "max LCP natural-map residual (dual path)"},
          {"max_kkt_complementarity", 0.0, "max KKT complementarity residual"},
          {"max_stationarity", 0.0, "max stationarity"},
          {"mean_stationarity", 0.0, "mean stationarity"},
          {"traj_error_rms", 0.0, "trajectory error (RMS / diagonal)"}};
}

// Whether a row is drawn: not the reference, and not a run that failed (its figures cover only
// the steps before the failure; the table keeps it with the reason).
inline bool IsPlotted(const ReportRow& r) {
  return r.family != "reference" && r.status.rfind("failed", 0) != 0;
}

// Panels of CandidatePanels() with at least one plottable point: a drawn row (IsPlotted) whose
// x column and value - offset are finite and positive (log axes).
inline std::vector<PlotPanel> SelectPanels(const std::vector<ReportRow>& rows,
                                           const std::string& x_column = "cpu_ms_frame_mean") {
  const ReportColumn& x = FindReportColumn(x_column);
  std::vector<PlotPanel> panels;
  for (const PlotPanel& panel : CandidatePanels()) {
    const ReportColumn& y = FindReportColumn(panel.column);
    for (const ReportRow& r : rows) {
      const double xv = x.get(r), yv = y.get(r) - panel.offset;
      if (IsPlotted(r) && std::isfinite(xv) && xv > 0.0 && std::isfinite(yv) && yv > 0.0) {
        panels.push_back(panel);
        break;
      }
    }
  }
  return panels;
}

// Legend text of a sweep family.
inline std::string DescribeFamily(const std::string& family) {
  if (family == "default") return "default settings";
  if (family == "pgs") return "PGS sweep cap";
  if (family == "newton") return "Newton cap";
  if (family == "penalty") return "penalty scale";
  if (family == "sqp") return "SQP iteration cap";
  if (family == "tol") return "SQP tolerance";
  if (family == "dt") return "time step";
  return family;
}

// Gnuplot single-quoted string literal ('' stands for one quote).
inline std::string QuoteGnuplot(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) quoted += c == '\'' ? std::string("''") : std::string(1, c);
  return quoted + "'";
}

// Legend text of a curve: the family and the path, e.g. "SQP iteration cap, primal".
inline std::string DescribeCurve(const SweepCurve& curve) {
  if (curve.family == "default") return "default settings, " + curve.solver;
  return DescribeFamily(curve.family) + ", " + curve.solver;
}

// Gnuplot colour of a family (the same on every path), as "rgb '#rrggbb'".
inline std::string FamilyColor(const std::string& family) {
  static const char* kFamilies[][2] = {
      {"pgs", "#7b3294"}, {"newton", "#1b9e77"}, {"penalty", "#a6611a"}, {"sqp", "#e66101"},
      {"tol", "#0571b0"}, {"dt", "#d01c8b"},     {"default", "#000000"}};
  for (const auto& f : kFamilies)
    if (family == f[0]) return std::string("rgb '") + f[1] + "'";
  return "rgb '#808080'";
}

// Gnuplot dash type and point type of a path: dual solid circles, primal dashed squares, auto
// dotted triangles (one less: the open form).
inline int SolverDash(const std::string& solver) {
  return solver == "primal" ? 2 : solver == "auto" ? 3 : 1;
}
inline int SolverPoint(const std::string& solver) {
  return solver == "primal" ? 5 : solver == "auto" ? 9 : 7;
}

// The script: a pngcairo multiplot, log-log, one panel per request panel (two columns), in each
// panel one linespoints line per curve labelled with the knob values (the default-settings
// points of each path as one large open point), the legend in the first panel only; failed runs
// are not drawn (IsPlotted). Throws
// InputError for no panels, no curves or an unknown column.
inline std::string MakeGnuplotScript(const PlotRequest& request) {
  TAUT_DEMAND(!request.panels.empty(), "MakeGnuplotScript: nothing to plot for '", request.title,
              "'");
  TAUT_DEMAND(!request.curves.empty(), "MakeGnuplotScript: no sweep family for '", request.title,
              "'");
  const int num_cols = request.panels.size() > 1 ? 2 : 1;
  const int num_rows = static_cast<int>((request.panels.size() + 1) / 2);
  const int x = FindCsvColumn(request.x_column);
  const int family = FindCsvColumn("family"), label = FindCsvColumn("label"),
            solver = FindCsvColumn("solver"), status = FindCsvColumn("status");
  std::string s = "# Generated by taut-report from " + request.csv_path + "; run: gnuplot FILE\n";
  s += "set terminal pngcairo noenhanced size " + std::to_string(560 * num_cols) + "," +
       std::to_string(60 + 400 * num_rows) + " font ',9'\n";
  s += "set output " + QuoteGnuplot(request.png_path) + "\n";
  s += "set datafile separator ','\n";
  s += "set logscale xy\nset format x '%g'\nset format y '%.0e'\nset grid\n";
  s += "set key top right font ',7' opaque\nset offsets graph 0.05, graph 0.05, graph 0.05, graph "
       "0.05\n";
  s += "set xlabel 'CPU time per simulated 1/60 s frame [ms] (" + request.x_column + ")'\n";
  s += "set multiplot layout " + std::to_string(num_rows) + "," + std::to_string(num_cols) +
       " title " + QuoteGnuplot(request.title) + "\n";
  const std::string data = QuoteGnuplot(request.csv_path);
  for (size_t k = 0; k < request.panels.size(); ++k) {
    const PlotPanel& panel = request.panels[k];
    if (k == 1) s += "unset key\n";  // the first panel's legend serves all
    const std::string y = "$" + std::to_string(FindCsvColumn(panel.column));
    char offset[32];
    std::snprintf(offset, sizeof(offset), "%.17g", panel.offset);
    const std::string yv = "(" + y + " - " + offset + ")";
    const std::string y_using = "(" + yv + " > 0 ? " + yv + " : NaN)";
    s += "set ylabel " + QuoteGnuplot(panel.ylabel) + "\nplot \\\n";
    for (size_t f = 0; f < request.curves.size(); ++f) {
      const SweepCurve& curve = request.curves[f];
      const bool lone = curve.family == "default";  // points of different paths: not joined
      const std::string color = FamilyColor(curve.family);
      const std::string x_using = "(strcol(" + std::to_string(family) + ") eq " +
                                  QuoteGnuplot(curve.family) + " && strcol(" +
                                  std::to_string(solver) + ") eq " + QuoteGnuplot(curve.solver) +
                                  " && strstrt(strcol(" + std::to_string(status) +
                                  "), 'failed') != 1 ? $" + std::to_string(x) + " : NaN)";
      s += "  " + std::string(f == 0 ? data : "''") + " skip 1 using " + x_using + ":" + y_using +
           " with " + (lone ? "points lw 1.5 ps 1.4" : "linespoints lw 1.5 ps 0.6") + " dt " +
           std::to_string(SolverDash(curve.solver)) + " pt " +
           std::to_string(SolverPoint(curve.solver) - (lone ? 1 : 0)) + " lc " + color + " title " +
           QuoteGnuplot(DescribeCurve(curve)) + ", \\\n";
      s += "  '' skip 1 using " + x_using + ":" + y_using + ":(strcol(" + std::to_string(label) +
           ")) with labels offset char 0.8,0.5 font ',7' tc " + color + " notitle" +
           (f + 1 < request.curves.size() ? ", \\\n" : "\n");
    }
  }
  s += "unset multiplot\n";
  return s;
}

}  // namespace taut
