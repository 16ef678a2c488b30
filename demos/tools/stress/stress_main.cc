// taut-stress: stability cells on stiff and extreme cases, written as a Markdown table.
//   taut-stress [--out docs/stress.md] [--filter TEXT] [--smoke] [--list] [--in-process]
//               [--timeout SECONDS] [--machine TEXT]
// Exit status: 0 when no cell is BROKEN (silent NaN, unexpected exception, crash or hang);
// degrading, loudly failing and pending cells are reported, not fatal.
#include <CLI/CLI.hpp>
#include <chrono>
#include <fstream>
#include <iostream>

#include "demos/tools/stress/stress_report.h"
#include "demos/tools/stress/stress_suite.h"

namespace {
#ifdef NDEBUG
constexpr const char* kBuildType = "Release";
#else
constexpr const char* kBuildType = "Debug";
#endif
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"taut stress suite: stiff and extreme cases, one table"};
  std::string out_path, filter;
  bool smoke = false, list = false, in_process = false;
  double timeout_s = 1800.0;
  std::string machine;
  app.add_option("--out", out_path, "write the Markdown report to this file");
  app.add_option("--filter", filter, "run only cells whose group or name contains this text");
  app.add_flag("--smoke", smoke, "a few short cells (seconds) instead of the full suite");
  app.add_flag("--list", list, "print the cells and exit");
  app.add_flag("--in-process", in_process, "run cells in this process (no crash isolation)");
  app.add_option("--timeout", timeout_s, "seconds one cell may take before it counts as a hang");
  app.add_option("--machine", machine, "the machine, for the report header");
  CLI11_PARSE(app, argc, argv);

  std::vector<taut::stress::SuiteCell> cells;
  for (auto& cell : smoke ? taut::stress::MakeSmokeSuite() : taut::stress::MakeFullSuite())
    if (filter.empty() || cell.group.find(filter) != std::string::npos ||
        cell.name.find(filter) != std::string::npos)
      cells.push_back(std::move(cell));
  if (list) {
    for (const auto& cell : cells) std::cout << cell.group << " / " << cell.name << "\n";
    return 0;
  }
  const auto start = std::chrono::steady_clock::now();
  std::vector<taut::stress::CellResult> results;
  int broken = 0;
  for (const auto& cell : cells) {
    results.push_back(taut::stress::RunSuiteCell(cell, !in_process, timeout_s));
    broken += results.back().status == taut::stress::CellStatus::kBroken;
    std::cout << taut::stress::FormatCellLine(results.back()) << std::endl;
  }
  taut::stress::ReportInfo info;
  info.command = "scripts/run_stress.sh";
  info.build_type = kBuildType;
  info.machine = machine;
  info.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << results.size() << " cells, " << broken << " broken, " << info.wall_s << " s\n";
  if (!out_path.empty()) {
    std::ofstream out(out_path);
    if (!out) {
      std::cerr << "error: cannot write " << out_path << "\n";
      return 2;
    }
    taut::stress::WriteMarkdownReport(results, info, out);
  }
  return broken == 0 ? 0 : 1;
}
