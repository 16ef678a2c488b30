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
  EXPECT_EQ(header.size(), ReportColumns().size() + 3);
  EXPECT_EQ(FindCsvColumn("family"), 1);
  EXPECT_EQ(FindCsvColumn("status"), static_cast<int>(header.size()));
  for (const char* name : {"max_violation", "ms_frame_mean", "steps", "max_lcp_residual"})
    EXPECT_EQ(header[FindCsvColumn(name) - 1], name);
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
  EXPECT_NE(table.find("| sqp | 1 (timeout at t = 0.2 s) |"), std::string::npos);
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
  header.has_lcp_residual = true;
  page = FormatReportMarkdown(header, {measured});
  EXPECT_EQ(page.find("do not carry the final LCP"), std::string::npos);
}

}  // namespace
}  // namespace taut
