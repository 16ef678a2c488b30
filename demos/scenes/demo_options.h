// Command-line checks, help text and the closing summary of taut-demo (demos/taut_demo.cc), kept
// here so that tests can call them.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "demos/scenes/scene.h"

namespace taut {

// What the user gave on the command line; unset options take the scene's defaults.
struct DemoArguments {
  std::string scene;
  std::optional<int> steps;
  std::optional<double> dt;  // [s]
  std::string out_dir;       // empty: out/<scene>
};

// A checked run: the scene and every value filled in.
struct DemoRun {
  const SceneInfo* scene = nullptr;
  int steps = 0;
  double dt = 0.0;
  std::string out_dir;
};

// Checks the arguments against the registry and fills in the defaults. Creates out_dir (and its
// parents) and probes that a file can be written there. Throws InputError with a one-line message
// naming the valid choices: an empty or unknown scene (lists the scenes), --steps or --dt not
// positive (or --dt not finite), an --out that cannot be created or written.
DemoRun ResolveDemoArguments(const DemoArguments& args);

// One line per scene, "  name  description", for --help.
std::string FormatSceneList();

// The short human-readable report printed at the end of a scene: steps and time step, median ms
// per step and per 1/60 s frame, wall time, unconverged steps, max violation, and the outputs found
// in out_dir (summary.json, steps.csv, ParaView collections *.pvd, pictures *.png / *.gif) with how
// to open them. `summary` is what summary.json holds.
std::string FormatRunReport(const nlohmann::json& summary, const std::string& out_dir);

}  // namespace taut
