// taut-report: for every registered scene, sweeps solver effort (PGS sweep cap, SQP iteration
// cap, SQP tolerance, time step) and records error against run time: a CSV and a log-log plot
// per scene in --out, and a markdown page with a table per scene (default docs/report.md).
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "demos/tools/report/report_files.h"
#include "demos/tools/report/scene_report.h"
#include "demos/tools/report/scene_run.h"

namespace {

// CPU model from /proc/cpuinfo ("unknown CPU" elsewhere).
std::string ReadCpuModel() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) != 0) continue;
    const size_t colon = line.find(':');
    if (colon != std::string::npos && colon + 2 <= line.size()) return line.substr(colon + 2);
  }
  return "unknown CPU";
}

// The scenes named in a comma list (all registered scenes when empty), in registry order.
std::vector<taut::SceneInfo> SelectScenes(const std::string& names) {
  if (names.empty()) return taut::SceneRegistry();
  std::vector<taut::SceneInfo> scenes;
  for (const std::string& name : taut::internal::SplitList(names, "--scenes"))
    scenes.push_back(taut::FindScene(name));
  return scenes;
}

// Command-line text of the run, for the page.
std::string JoinArguments(int argc, char** argv) {
  std::string text = "taut-report";
  for (int i = 1; i < argc; ++i) text += std::string(" ") + argv[i];
  return text;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"taut-report: error against run time of every scene over a sweep of solver effort"};
  std::string out_dir = "docs/report", page, scenes, pgs, sqp, tolerances, divisors;
  bool quick = false, smoke = false;
  int steps = 0, reference_divisor = 0;
  double duration = 0.0, reference_budget = 0.0, run_budget = 0.0;
  app.add_option("--out", out_dir, "Folder of the CSVs, gnuplot scripts and PNGs")
      ->capture_default_str();
  app.add_option("--markdown", page, "Markdown page to write (default: <out>.md)");
  app.add_option("--scenes", scenes, "Comma list of scenes (default: every registered scene)");
  app.add_flag("--quick", quick, "Half a second per scene and a coarse sweep (minutes)");
  app.add_flag("--smoke", smoke, "A few steps and a minimal sweep (seconds; for ctest)");
  app.add_option("--steps", steps, "Steps of the scene's dt per run (overrides --duration)")
      ->check(CLI::PositiveNumber);
  app.add_option("--duration", duration,
                 "Simulated time per run in s (default 1, quick 0.5; the reference may cut it)")
      ->check(CLI::PositiveNumber);
  app.add_option("--pgs-sweeps", pgs, "PGS sweep caps, e.g. 5,10,20,50,100,400");
  app.add_option("--sqp-iterations", sqp, "SQP iteration caps, e.g. 1,2,4,10,20");
  app.add_option("--tolerance-factors", tolerances,
                 "SQP tolerances as factors of the scene's, e.g. 10,1,0.1,0.01");
  app.add_option("--dt-divisors", divisors, "Time steps dt/k, e.g. 1,2,4");
  app.add_option("--reference-divisor", reference_divisor, "Reference time step dt/k (default 8)")
      ->check(CLI::PositiveNumber);
  app.add_option("--reference-budget", reference_budget,
                 "CPU seconds of a reference run; where it stops sets the simulated time")
      ->check(CLI::PositiveNumber);
  app.add_option("--run-budget", run_budget, "CPU seconds after which a sweep run stops")
      ->check(CLI::PositiveNumber);
  CLI11_PARSE(app, argc, argv);
  const auto start = std::chrono::steady_clock::now();
  try {
    TAUT_DEMAND(!(quick && smoke), "--quick and --smoke exclude each other");
    taut::SceneReportOptions options;
    if (quick) {
      options.lists = {{5, 20, 100}, {1, 4, 20}, {10, 0.1}, {1, 2}, 4};
      options.duration_s = 0.5;
      options.reference_budget_s = 20.0;
      options.run_budget_s = 30.0;
    } else if (smoke) {
      options.lists = {{5, 100}, {1}, {1}, {1, 2}, 2};
      options.steps = 2;
      options.reference_budget_s = 1.0;
      options.run_budget_s = 1.0;
    }
    if (!pgs.empty()) options.lists.pgs_sweeps = taut::ParsePositiveIntList(pgs, "--pgs-sweeps");
    if (!sqp.empty())
      options.lists.sqp_iterations = taut::ParsePositiveIntList(sqp, "--sqp-iterations");
    if (!tolerances.empty())
      options.lists.tolerance_factors =
          taut::ParsePositiveDoubleList(tolerances, "--tolerance-factors");
    if (!divisors.empty())
      options.lists.dt_divisors = taut::ParsePositiveIntList(divisors, "--dt-divisors");
    if (reference_divisor > 0) options.lists.reference_divisor = reference_divisor;
    if (steps > 0) options.steps = steps;
    if (duration > 0.0) options.duration_s = duration;
    if (reference_budget > 0.0) options.reference_budget_s = reference_budget;
    if (run_budget > 0.0) options.run_budget_s = run_budget;
    while (out_dir.size() > 1 && out_dir.back() == '/') out_dir.pop_back();
    if (page.empty()) page = out_dir + ".md";
    options.out_dir = out_dir;
    const std::filesystem::path page_path(page);
    options.page_dir = page_path.has_parent_path() ? page_path.parent_path().string() : ".";
    std::filesystem::create_directories(options.out_dir);
    std::filesystem::create_directories(options.page_dir);

    std::vector<taut::SceneSection> sections;
    for (const taut::SceneInfo& info : SelectScenes(scenes))
      sections.push_back(taut::MeasureScene(info, options));
    taut::ReportHeader header;
    header.command = JoinArguments(argc, argv);
    header.machine = ReadCpuModel();
#ifdef NDEBUG
    header.build = "optimized build";
#else
    header.build = "build with assertions: timings are not representative";
#endif
    header.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    header.lists = options.lists;
    header.has_lcp_residual = taut::StepStatsHaveLcpResidual();
    taut::WriteTextFile(page, taut::FormatReportMarkdown(header, sections));
    std::fprintf(stderr, "taut-report: wrote %s and %s/ in %.1f s\n", page.c_str(), out_dir.c_str(),
                 header.wall_s);
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "taut-report: " << e.what() << "\n";
    return 1;
  }
}
