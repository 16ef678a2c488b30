#include "demos/tools/report/report_table.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <sstream>

#include "demos/tools/report/report_markdown.h"

namespace taut {
namespace {

// Fields of one CSV line.
std::vector<std::string> SplitCsv(const std::string& line) {
  std::vector<std::string> fields;
  std::stringstream in(line);
  std::string field;
  while (std::getline(in, field, ',')) fields.push_back(field);
  return fields;
}

// A row with a few figures set.
ReportRow MakeRow(const std::string& family, const std::string& label) {
  ReportRow row;
  row.family = family;
  row.label = label;
  row.solver = "dual";
  row.dt = 1.0 / 240.0;
  row.steps = 120;
  row.ms_frame_mean = 12.5;
  row.max_violation = 2.5e-3;
  row.max_penetration = 0.004;
  row.traj_error_rms = 1e-3;
  return row;
}

// Header and rows have the same fields, FindCsvColumn points at them, missing figures are "nan"
// and commas in text cannot shift the columns.
TEST(ReportTableTest, CsvColumnsLineUp) {
  ReportRow row = MakeRow("pgs", "5");
  row.status = "failed at t = 0.1 s: node 3, stage integrate";
  const std::vector<std::string> header = SplitCsv(FormatCsvHeader());
  const std::vector<std::string> fields = SplitCsv(FormatCsvRow(row));
  ASSERT_EQ(header.size(), fields.size());
  EXPECT_EQ(header.size(), ReportColumns().size() + 4);
  EXPECT_EQ(FindCsvColumn("family"), 1);
  EXPECT_EQ(FindCsvColumn("solver"), 3);
  EXPECT_EQ(fields[2], "dual");
  EXPECT_EQ(FindCsvColumn("status"), static_cast<int>(header.size()));
  for (const char* name : {"max_violation", "ms_frame_mean", "steps", "max_lcp_residual",
                           "mean_newton_iterations", "max_kkt_dual", "penalty_scale"})
    EXPECT_EQ(header[FindCsvColumn(name) - 1], name);
  EXPECT_EQ(std::string(FindReportColumn("max_kkt_primal").name), "max_kkt_primal");
  EXPECT_THROW(FindReportColumn("solver"), InputError);  // text, not a number
  EXPECT_EQ(std::stod(fields[FindCsvColumn("max_violation") - 1]), 2.5e-3);
  EXPECT_EQ(fields[FindCsvColumn("steps") - 1], "120");
  EXPECT_EQ(fields[FindCsvColumn("max_lcp_residual") - 1], "nan");
  EXPECT_EQ(fields.back(), "failed at t = 0.1 s: node 3  stage integrate");
  EXPECT_THROW(FindCsvColumn("no_such_column"), InputError);
}

// The markdown table keeps only columns some row has, shows dt in ms and penetration in mm, and
// marks runs that did not finish.
TEST(ReportTableTest, MarkdownTableShowsWhatExists) {
  ReportRow failed = MakeRow("sqp", "1");
  failed.status = "timeout at t = 0.2 s";
  const std::string table = FormatMarkdownTable({MakeRow("pgs", "5"), failed});
  EXPECT_NE(table.find("| max viol. |"), std::string::npos);
  EXPECT_EQ(table.find("LCP"), std::string::npos);  // NaN in every row: left out
  EXPECT_EQ(table.find("max U/Umax"), std::string::npos);
  ReportRow limited = MakeRow("tol", "0.01");
  limited.max_energy_ratio = 1.00097;
  EXPECT_NE(FormatMarkdownTable({limited}).find("| 1.0010 |"), std::string::npos);
  EXPECT_NE(table.find("| 4.17 |"), std::string::npos);  // dt = 1/240 s in ms
  EXPECT_NE(table.find("| 4 |"), std::string::npos);     // 0.004 m in mm
  EXPECT_NE(table.find("| sqp | 1 (timeout at t = 0.2 s) | dual |"), std::string::npos);
  EXPECT_NE(table.find("| family | setting | solver |"), std::string::npos);
  EXPECT_EQ(table.find("Newton it."), std::string::npos);  // NaN in every row: left out
  ReportRow primal = MakeRow("newton", "4");
  primal.solver = "primal";
  primal.mean_newton_iterations = 6.5;
  primal.max_kkt_complementarity = 2e-4;
  const std::string both = FormatMarkdownTable({MakeRow("pgs", "5"), primal});
  EXPECT_NE(both.find("| Newton it. |"), std::string::npos);
  EXPECT_NE(both.find("| KKT compl. |"), std::string::npos);
  EXPECT_NE(both.find("| newton | 4 | primal |"), std::string::npos);
  EXPECT_NE(both.find("| 6.5 |"), std::string::npos);
  EXPECT_EQ(std::count(table.begin(), table.end(), '\n'), 4);  // header, rule, two rows
  EXPECT_EQ(FormatFigure(-0.0, false), "0");
  EXPECT_EQ(FormatFigure(ReportRow::kNaN, false), "–");
}

// The page has the method, one section per scene with its table, plot and CSV links, the
// reason a scene was skipped, and the LCP note only while StepStats lacks the residual.
TEST(ReportTableTest, MarkdownPageLinksEveryScene) {
  ReportHeader header;
  header.command = "taut-report --quick";
  header.machine = "test CPU";
  SceneSection measured;
  measured.name = "hex_beam";
  measured.description = "beams";
  measured.duration_s = 0.5;
  measured.dt = 1.0 / 240.0;
  measured.reference = "dt/8";
  measured.rows = {MakeRow("pgs", "5")};
  measured.csv_link = "report/hex_beam.csv";
  measured.png_link = "report/hex_beam.png";
  SceneSection skipped;
  skipped.name = "armadillo";
  skipped.skipped = "data/armadillo.off is missing";
  std::string page = FormatReportMarkdown(header, {measured, skipped});
  EXPECT_NE(page.find("`taut-report --quick`"), std::string::npos);
  EXPECT_NE(page.find("## hex_beam"), std::string::npos);
  EXPECT_NE(page.find("![hex_beam](report/hex_beam.png)"), std::string::npos);
  EXPECT_NE(page.find("[report/hex_beam.csv](report/hex_beam.csv)"), std::string::npos);
  EXPECT_NE(page.find("| pgs | 5 |"), std::string::npos);
  EXPECT_NE(page.find("Not measured: data/armadillo.off is missing"), std::string::npos);
  EXPECT_NE(page.find("do not carry the final LCP"), std::string::npos);
  EXPECT_EQ(page.find("## Summary"), std::string::npos);  // no default-settings rows
  header.has_lcp_residual = true;
  page = FormatReportMarkdown(header, {measured});
  EXPECT_EQ(page.find("do not carry the final LCP"), std::string::npos);
  header.sweep_note = "Coarse sweep (`--quick`).";
  page = FormatReportMarkdown(header, {measured});
  EXPECT_LT(page.find("Coarse sweep (`--quick`)."), page.find("## Method"));
}

// The summary names, per scene, the better path by trajectory error (uncertified steps break a
// tie) and by CPU time per frame, with the figures, and lists the auto path when it ran.
TEST(ReportTableTest, SummaryComparesThePaths) {
  SceneSection scene;
  scene.name = "tet_beam";
  ReportRow dual = MakeRow("default", "dual");
  dual.unconverged_steps = 10;
  dual.cpu_ms_frame_mean = 60.0;
  dual.traj_error_rms = 2e-3;
  ReportRow primal = dual;
  primal.label = primal.solver = "primal";
  primal.unconverged_steps = 0;
  primal.cpu_ms_frame_mean = 90.0;
  primal.traj_error_rms = 1e-3;
  ReportRow automatic = primal;
  automatic.label = automatic.solver = "auto";
  ReportRow accurate = MakeRow("dt", "dt/2");
  accurate.solver = "primal";
  accurate.traj_error_rms = 1e-4;
  accurate.cpu_ms_frame_mean = 180.0;
  ReportRow stopped = accurate;
  stopped.traj_error_rms = 1e-5;
  stopped.status = "timeout at t = 0.1 s";  // cut short: not comparable
  scene.rows = {dual, primal, automatic, accurate, stopped};
  std::string summary = FormatSolverSummary({scene});
  EXPECT_NE(summary.find("- **tet_beam**: error: **primal**, traj. err. 0.002 (dual) vs 0.001 "
                         "(primal), uncertified steps 10 vs 0"),
            std::string::npos)
      << summary;
  EXPECT_NE(summary.find("time: **dual**, CPU ms/frame 60 vs 90 (primal/dual 1.5)"),
            std::string::npos)
      << summary;
  EXPECT_NE(summary.find("| tet_beam | auto | 0 of 120 |"), std::string::npos) << summary;
  EXPECT_NE(summary.find("| 0.0001 (dt dt/2, 180) |"), std::string::npos) << summary;
  // Equal errors: the uncertified steps decide; equal cost within 10 %: a tie.
  scene.rows[1].traj_error_rms = 1.95e-3;
  scene.rows[1].cpu_ms_frame_mean = 63.0;
  summary = FormatSolverSummary({scene});
  EXPECT_NE(summary.find("error: **primal**"), std::string::npos) << summary;
  EXPECT_NE(summary.find("time: tie (within 10 %)"), std::string::npos) << summary;
  scene.rows[1].unconverged_steps = 10;
  EXPECT_NE(FormatSolverSummary({scene}).find("error: tie (within 10 %)"), std::string::npos);
}

}  // namespace
}  // namespace taut
