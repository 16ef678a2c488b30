// taut-report: for every registered scene, sweeps solver effort (PGS sweep cap or Newton cap and
// penalty, SQP iteration cap, SQP tolerance, time step) on each island solver path (dual,
// primal) and records error against run time: a CSV and a log-log plot per scene in --out, and a
// markdown page with a table per scene and a dual-against-primal summary (default
// docs/report.md).
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
  std::string newton, penalties, solvers, reference_solver;
  bool quick = false, smoke = false, no_auto = false;
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
  app.add_option("--newton-iterations", newton, "Primal Newton caps, e.g. 1,2,4,12,30");
  app.add_option("--penalty-scales", penalties, "Primal penalty scales, e.g. 10,100,1000,10000");
  app.add_option("--solvers", solvers,
                 "Island solver paths every family is swept on (default dual,primal; add auto)");
  app.add_flag("--no-auto", no_auto, "No run of the auto path at the default settings");
  app.add_option("--reference-solver", reference_solver,
                 "Path of the reference run: primal (default), dual or auto");
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
    std::string sweep_note;
    taut::SweepLists& lists = options.lists;
    if (quick) {
      lists.pgs_sweeps = {5, 20, 100};
      lists.sqp_iterations = {1, 4, 20};
      lists.tolerance_factors = {10, 0.1};
      lists.dt_divisors = {1, 2};
      lists.reference_divisor = 4;
      lists.newton_iterations = {1, 4, 12};
      lists.penalty_scales = {100, 1e4};
      options.duration_s = 0.5;
      options.reference_budget_s = 20.0;
      options.run_budget_s = 30.0;
      sweep_note =
          "Coarse sweep (`--quick`): at most 0.5 s simulated per scene, short knob lists, a dt/4 "
          "reference and 20 s / 30 s CPU budgets for the reference and each run. The full sweep "
          "(`scripts/run_report.sh` without options) runs every family on both paths, about "
          "twice the runs of the dual-only report, whose full sweep alone took 10-15 min.";
    } else if (smoke) {
      lists.pgs_sweeps = {5, 100};
      lists.sqp_iterations = {1};
      lists.tolerance_factors = {1};
      lists.dt_divisors = {1, 2};
      lists.reference_divisor = 2;
      lists.newton_iterations = {2};
      lists.penalty_scales = {};
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
    if (!newton.empty())
      lists.newton_iterations = taut::ParsePositiveIntList(newton, "--newton-iterations");
    if (!penalties.empty())
      lists.penalty_scales = taut::ParsePositiveDoubleList(penalties, "--penalty-scales");
    if (!solvers.empty()) lists.solvers = taut::ParseSolverList(solvers, "--solvers");
    if (no_auto) lists.auto_default = false;
    if (!reference_solver.empty()) {
      const std::vector<taut::IslandSolverKind> kinds =
          taut::ParseSolverList(reference_solver, "--reference-solver");
      TAUT_DEMAND(kinds.size() == 1, "--reference-solver takes one path, not '", reference_solver,
                  "'");
      lists.reference_solver = kinds[0];
    }
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
    header.sweep_note = sweep_note;
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
