// Files taut-report writes: the scene CSV, the gnuplot script and its PNG, the markdown page.
#pragma once

#include <string>
#include <vector>

#include "demos/tools/report/report_table.h"
#include "demos/tools/report/sweep_plan.h"

namespace taut {

// Writes the header and one line per row to `path`; throws InputError when it cannot.
void WriteReportCsv(const std::string& path, const std::vector<ReportRow>& rows);

// Result of WriteReportPlot.
struct PlotFiles {
  std::string png;   // path of the image, empty when none was drawn
  std::string note;  // why not, or empty
};

// Writes <dir>/<name>.gp (reading <name>.csv in dir) and runs gnuplot in dir to draw
// <dir>/<name>.png. Without gnuplot, or with nothing plottable, says so in the note instead.
PlotFiles WriteReportPlot(const std::string& dir, const std::string& name,
                          const std::vector<ReportRow>& rows,
                          const std::vector<SweepCurve>& curves);

// Writes text to path; throws InputError when it cannot.
void WriteTextFile(const std::string& path, const std::string& text);

// Whether a gnuplot executable is on PATH.
bool HasGnuplot();

}  // namespace taut
