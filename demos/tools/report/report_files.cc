#include "demos/tools/report/report_files.h"

#include <cstdlib>
#include <fstream>

#include "demos/tools/report/plot_script.h"

namespace taut {

namespace {
// Shell single-quoted form of text.
std::string QuoteShell(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}
}  // namespace

void WriteTextFile(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  TAUT_DEMAND(out.good(), "cannot write '", path, "'");
  out << text;
  out.close();
  TAUT_DEMAND(out.good(), "writing '", path, "' failed");
}

void WriteReportCsv(const std::string& path, const std::vector<ReportRow>& rows) {
  std::string text = FormatCsvHeader() + "\n";
  for (const ReportRow& row : rows) text += FormatCsvRow(row) + "\n";
  WriteTextFile(path, text);
}

bool HasGnuplot() { return std::system("command -v gnuplot > /dev/null 2>&1") == 0; }

PlotFiles WriteReportPlot(const std::string& dir, const std::string& name,
                          const std::vector<ReportRow>& rows,
                          const std::vector<SweepCurve>& curves) {
  PlotFiles files;
  PlotRequest request;
  request.csv_path = name + ".csv";
  request.png_path = name + ".png";
  request.title = name + ": error against CPU time per simulated frame (log-log)";
  request.curves = curves;
  request.panels = SelectPanels(rows, request.x_column);
  if (request.panels.empty()) {
    files.note = "No plot: no error is positive in any run.";
    return files;
  }
  WriteTextFile(dir + "/" + name + ".gp", MakeGnuplotScript(request));
  if (!HasGnuplot()) {
    files.note =
        "No plot: gnuplot was not found; draw it with `cd " + dir + " && gnuplot " + name + ".gp`.";
    return files;
  }
  const std::string command =
      "cd " + QuoteShell(dir) + " && gnuplot " + QuoteShell(name + ".gp") + " > /dev/null 2>&1";
  if (std::system(command.c_str()) != 0) {
    files.note = "No plot: gnuplot failed on " + name + ".gp (run it by hand to see why).";
    return files;
  }
  files.png = dir + "/" + request.png_path;
  return files;
}

}  // namespace taut
