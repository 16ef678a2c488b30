#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "demos/tools/report/plot_script.h"

namespace taut {
namespace {

// A plottable row of `family`.
ReportRow MakeRow(const std::string& family, const std::string& label, double ms,
                  double violation) {
  ReportRow row;
  row.family = family;
  row.label = label;
  row.solver = "dual";
  row.cpu_ms_frame_mean = ms;
  row.max_violation = violation;
  row.traj_error_rms = 0.1 / ms;
  return row;
}

// Occurrences of `part` in text.
int Count(const std::string& text, const std::string& part) {
  int n = 0;
  for (size_t at = text.find(part); at != std::string::npos; at = text.find(part, at + 1)) ++n;
  return n;
}

// A panel is drawn only when a non-reference row has a positive value (log axes); U/Umax is
// drawn as its overshoot over 1.
TEST(ReportPlotScriptTest, SelectsPanelsWithPositiveValues) {
  std::vector<ReportRow> rows = {MakeRow("pgs", "5", 10.0, 0.0), MakeRow("pgs", "50", 20.0, 0.0)};
  ReportRow reference = MakeRow("reference", "dt/8", 100.0, 1e-3);
  reference.max_stationarity = 0.5;
  rows.push_back(reference);
  ReportRow failed = MakeRow("newton", "1", 5.0, 3.0);
  failed.max_kkt_complementarity = 2.0;
  failed.status = "failed at t = 0.05 s: body 'beam': node 67 moves at 1e+06 m/s";
  rows.push_back(failed);  // a failed run is not drawn, so it adds no panel
  EXPECT_FALSE(IsPlotted(failed));
  EXPECT_FALSE(IsPlotted(reference));
  rows[0].max_energy_ratio = 0.97;  // below the limit: nothing to plot
  std::vector<PlotPanel> panels = SelectPanels(rows);
  ASSERT_EQ(panels.size(), 1u);
  EXPECT_EQ(panels[0].column, "traj_error_rms");
  rows[1].max_energy_ratio = 1.02;
  rows[1].max_violation = 0.02;
  panels = SelectPanels(rows);
  ASSERT_EQ(panels.size(), 3u);
  EXPECT_EQ(panels[0].column, "max_violation");
  EXPECT_EQ(panels[1].column, "max_energy_ratio");
  EXPECT_EQ(panels[1].offset, 1.0);
  rows[0].cpu_ms_frame_mean = rows[1].cpu_ms_frame_mean =
      ReportRow::kNaN;  // no cost: nothing at all
  EXPECT_TRUE(SelectPanels(rows).empty());
}

// The script draws every panel with one line and one label set per (family, solver) curve, from
// the right CSV columns, log-log, into the requested PNG, the legend in the first panel only;
// nothing to draw throws.
TEST(ReportPlotScriptTest, ScriptHasOneLinePerCurveAndPanel) {
  PlotRequest request;
  request.csv_path = "it's.csv";
  request.png_path = "scene.png";
  request.title = "scene";
  request.curves = {{"pgs", "dual"}, {"sqp", "dual"}, {"dt", "primal"}};
  request.panels = {{"max_violation", 0.0, "violation"},
                    {"max_energy_ratio", 1.0, "U - 1"},
                    {"traj_error_rms", 0.0, "error"}};
  const std::string script = MakeGnuplotScript(request);
  EXPECT_NE(script.find("set logscale xy"), std::string::npos);
  EXPECT_NE(script.find("set output 'scene.png'"), std::string::npos);
  EXPECT_NE(script.find("'it''s.csv'"), std::string::npos);  // quote doubled
  EXPECT_NE(script.find("set multiplot layout 2,2"), std::string::npos);
  EXPECT_EQ(Count(script, "\nplot "), 3);
  EXPECT_EQ(Count(script, "with linespoints"), 9);
  EXPECT_EQ(Count(script, "with labels"), 9);
  EXPECT_EQ(Count(script, "title 'SQP iteration cap, dual'"), 3);
  EXPECT_EQ(Count(script, "title 'time step, primal'"), 3);
  EXPECT_EQ(Count(script, "unset key"), 1);
  const std::string x = "$" + std::to_string(FindCsvColumn("cpu_ms_frame_mean"));
  const std::string y = "$" + std::to_string(FindCsvColumn("max_energy_ratio"));
  const std::string solver = std::to_string(FindCsvColumn("solver"));
  const std::string status = std::to_string(FindCsvColumn("status"));
  EXPECT_NE(script.find("eq 'dt' && strcol(" + solver + ") eq 'primal' && strstrt(strcol(" +
                        status + "), 'failed') != 1 ? " + x + " : NaN"),
            std::string::npos);
  // Same family on both paths: same colour, other dash type.
  request.curves = {{"sqp", "dual"}, {"sqp", "primal"}, {"default", "auto"}};
  const std::string two = MakeGnuplotScript(request);
  EXPECT_EQ(Count(two, "dt 1 pt 7 lc " + FamilyColor("sqp")), 3);
  EXPECT_EQ(Count(two, "dt 2 pt 5 lc " + FamilyColor("sqp")), 3);
  EXPECT_EQ(Count(two, "with points"), 3);  // the default-settings point is not joined
  EXPECT_NE(FamilyColor("sqp"), FamilyColor("tol"));
  EXPECT_NE(script.find("(" + y + " - 1) > 0"), std::string::npos);
  request.panels.clear();
  EXPECT_THROW(MakeGnuplotScript(request), InputError);
}

// Gnuplot accepts the script and draws the PNG (skipped without gnuplot).
TEST(ReportPlotScriptTest, GnuplotDrawsThePng) {
  if (std::system("command -v gnuplot > /dev/null 2>&1") != 0) GTEST_SKIP() << "no gnuplot";
  const std::string dir = ::testing::TempDir() + "/report_plot_script_test";
  std::filesystem::create_directories(dir);
  std::filesystem::remove(dir + "/scene.png");
  std::vector<ReportRow> rows = {MakeRow("pgs", "5", 10.0, 1e-2), MakeRow("pgs", "50", 30.0, 1e-3),
                                 MakeRow("dt", "dt/2", 20.0, ReportRow::kNaN),
                                 MakeRow("dt", "dt/2", 25.0, 2e-3)};
  rows.back().solver = "primal";
  rows.push_back(MakeRow("dt", "dt", 5.0, 1.0));
  rows.back().solver = "primal";
  rows.back().status = "failed at t = 0.1 s: node 3, stage integrate";
  std::ofstream csv(dir + "/scene.csv");
  csv << FormatCsvHeader() << "\n";
  for (const ReportRow& row : rows) csv << FormatCsvRow(row) << "\n";
  csv.close();
  PlotRequest request;
  request.csv_path = "scene.csv";
  request.png_path = "scene.png";
  request.title = "scene";
  request.curves = {{"pgs", "dual"}, {"dt", "dual"}, {"dt", "primal"}};
  request.panels = SelectPanels(rows);
  std::ofstream(dir + "/scene.gp") << MakeGnuplotScript(request);
  ASSERT_EQ(std::system(("cd '" + dir + "' && gnuplot scene.gp 2> gnuplot.log").c_str()), 0);
  ASSERT_TRUE(std::filesystem::exists(dir + "/scene.png"));
  EXPECT_GT(std::filesystem::file_size(dir + "/scene.png"), 1000u);
}

}  // namespace
}  // namespace taut
