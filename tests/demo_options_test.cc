// taut-demo's argument checks (one-line errors naming the valid choices), --help's scene list and
// the closing report of a run (demos/scenes/demo_options.h).
#include "demos/scenes/demo_options.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

namespace taut {
namespace {

namespace fs = std::filesystem;

// A writable scratch folder for --out.
std::string ScratchDir(const std::string& name) {
  const fs::path dir = fs::path(::testing::TempDir()) / name;
  fs::remove_all(dir);
  return dir.string();
}

// The InputError message of ResolveDemoArguments(args), or "" when it did not throw.
std::string ErrorOf(const DemoArguments& args) {
  try {
    ResolveDemoArguments(args);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// Every registered scene name appears in text.
void ExpectNamesEveryScene(const std::string& text) {
  for (const SceneInfo& info : SceneRegistry())
    EXPECT_NE(text.find(info.name), std::string::npos) << info.name << " missing in: " << text;
}

TEST(DemoOptionsTest, FillsTheScenesDefaultsAndCreatesTheOutputFolder) {
  DemoArguments args;
  args.scene = "tet_beam";
  args.out_dir = ScratchDir("demo_options_defaults") + "/nested/out";
  const DemoRun run = ResolveDemoArguments(args);
  ASSERT_NE(run.scene, nullptr);
  EXPECT_EQ(run.scene->name, "tet_beam");
  EXPECT_EQ(run.steps, run.scene->default_steps);
  EXPECT_EQ(run.dt, run.scene->default_dt);
  EXPECT_TRUE(fs::is_directory(args.out_dir));
  EXPECT_TRUE(fs::is_empty(args.out_dir));  // the write probe is removed
  args.steps = 3;
  args.dt = 0.002;
  const DemoRun given = ResolveDemoArguments(args);
  EXPECT_EQ(given.steps, 3);
  EXPECT_EQ(given.dt, 0.002);
}

TEST(DemoOptionsTest, UnknownOrMissingSceneGetsOneLineListingTheScenes) {
  DemoArguments args;
  args.scene = "tet_bean";
  args.out_dir = ScratchDir("demo_options_unknown");
  const std::string unknown = ErrorOf(args);
  EXPECT_NE(unknown.find("unknown scene 'tet_bean'"), std::string::npos) << unknown;
  ExpectNamesEveryScene(unknown);
  EXPECT_EQ(unknown.find('\n'), std::string::npos) << unknown;
  args.scene.clear();
  const std::string missing = ErrorOf(args);
  ExpectNamesEveryScene(missing);
  EXPECT_EQ(missing.find('\n'), std::string::npos);
}

TEST(DemoOptionsTest, NonPositiveStepsOrTimeStepIsAOneLineError) {
  DemoArguments args;
  args.scene = "hex_beam";
  args.out_dir = ScratchDir("demo_options_values");
  for (int steps : {0, -3}) {
    args.steps = steps;
    const std::string error = ErrorOf(args);
    EXPECT_NE(error.find("--steps must be a positive"), std::string::npos)
        << steps << ": " << error;
    EXPECT_EQ(error.find('\n'), std::string::npos);
  }
  args.steps.reset();
  for (double dt : {0.0, -0.01, std::numeric_limits<double>::quiet_NaN(),
                    std::numeric_limits<double>::infinity()}) {
    args.dt = dt;
    const std::string error = ErrorOf(args);
    EXPECT_NE(error.find("--dt must be a positive"), std::string::npos) << dt << ": " << error;
    EXPECT_EQ(error.find('\n'), std::string::npos);
  }
}

TEST(DemoOptionsTest, UnwritableOutputFolderIsAOneLineError) {
  // A path below a regular file cannot be created, even by root.
  const std::string dir = ScratchDir("demo_options_unwritable");
  fs::create_directories(dir);
  std::ofstream(dir + "/file") << "x";
  DemoArguments args;
  args.scene = "tet_beam";
  for (const std::string& out : {dir + "/file/sub", dir + "/file"}) {
    args.out_dir = out;
    const std::string error = ErrorOf(args);
    EXPECT_NE(error.find("--out '" + out + "'"), std::string::npos) << error;
    EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  }
}

TEST(DemoOptionsTest, SceneListHasOneLinePerScene) {
  const std::string list = FormatSceneList();
  ExpectNamesEveryScene(list);
  EXPECT_EQ(static_cast<size_t>(std::count(list.begin(), list.end(), '\n')),
            SceneRegistry().size());
}

TEST(DemoOptionsTest, RunReportNamesTheKeyFiguresAndTheOutputsFound) {
  const std::string dir = ScratchDir("demo_options_report");
  fs::create_directories(dir);
  std::ofstream(dir + "/beam.pvd") << "";
  std::ofstream(dir + "/tet_beam_end.png") << "";
  nlohmann::json summary = {{"scene", "tet_beam"},      {"steps", 480},
                            {"dt", 1.0 / 240.0},        {"ms_per_step_median", 1.25},
                            {"ms_per_frame_60hz", 5.0}, {"wall_time_s", 0.7},
                            {"unconverged_steps", 2},   {"max_violation", 3.5e-4}};
  const std::string report = FormatRunReport(summary, dir);
  for (const std::string& part :
       {std::string("tet_beam: 480 steps"), std::string("1.25 ms per step"),
        std::string("2 unconverged steps"), std::string("max violation 0.00035"),
        std::string("summary.json"), std::string("steps.csv"), std::string("beam.pvd"),
        std::string("paraview"), std::string("tet_beam_end.png")})
    EXPECT_NE(report.find(part), std::string::npos) << part << " missing in:\n" << report;
  EXPECT_LE(std::count(report.begin(), report.end(), '\n'), 6);
  fs::remove(dir + "/beam.pvd");
  EXPECT_NE(FormatRunReport(summary, dir).find("add --vtk"), std::string::npos);
}

}  // namespace
}  // namespace taut
