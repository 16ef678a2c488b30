#include "demos/scenes/demo_options.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <system_error>
#include <vector>

namespace taut {

namespace {

// "a, b, c" of every registered scene name.
std::string JoinSceneNames() {
  std::string names;
  for (const SceneInfo& info : SceneRegistry()) names += (names.empty() ? "" : ", ") + info.name;
  return names;
}

// Creates dir and writes and removes a probe file in it; throws InputError naming dir otherwise.
void DemandWritableFolder(const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir, ec);
  TAUT_DEMAND(!ec, "--out '", dir, "' cannot be created (", ec.message(),
              "); give a folder you can write to, e.g. --out out/demo");
  TAUT_DEMAND(fs::is_directory(dir, ec), "--out '", dir,
              "' is not a folder; give a folder you can write to, e.g. --out out/demo");
  const fs::path probe = fs::path(dir) / ".taut-demo-write-test";
  bool ok = false;
  {
    std::ofstream out(probe);
    out << "probe\n";
    out.close();
    ok = !out.fail();
  }
  fs::remove(probe, ec);
  TAUT_DEMAND(ok, "--out '", dir,
              "' is not writable; give a folder you can write to, e.g. --out out/demo");
}

// Shortest readable form of a number with `digits` significant digits.
std::string FormatNumber(double value, int digits = 3) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.*g", digits, value);
  return text;
}

}  // namespace

DemoRun ResolveDemoArguments(const DemoArguments& args) {
  TAUT_DEMAND(!args.scene.empty(), "name a scene; one of: ", JoinSceneNames());
  const SceneInfo* info = nullptr;
  for (const SceneInfo& candidate : SceneRegistry())
    if (candidate.name == args.scene) info = &candidate;
  TAUT_DEMAND(info != nullptr, "unknown scene '", args.scene,
              "'; valid scenes: ", JoinSceneNames());
  TAUT_DEMAND(!args.steps || *args.steps > 0, "--steps must be a positive number of steps, got ",
              *args.steps, " (scene ", info->name, " defaults to ", info->default_steps, ")");
  TAUT_DEMAND(!args.dt || (std::isfinite(*args.dt) && *args.dt > 0.0),
              "--dt must be a positive time step in seconds, got ", args.dt ? *args.dt : 0.0,
              " (scene ", info->name, " defaults to ", info->default_dt, ")");
  DemoRun run;
  run.scene = info;
  run.steps = args.steps.value_or(info->default_steps);
  run.dt = args.dt.value_or(info->default_dt);
  run.out_dir = args.out_dir.empty() ? "out/" + info->name : args.out_dir;
  DemandWritableFolder(run.out_dir);
  return run;
}

std::string FormatSceneList() {
  size_t width = 0;
  for (const SceneInfo& info : SceneRegistry()) width = std::max(width, info.name.size());
  std::string text;
  for (const SceneInfo& info : SceneRegistry()) {
    // The description, shortened at a word boundary so each scene fits one line.
    constexpr size_t kMaxLength = 90;
    std::string line = info.description;
    if (line.size() > kMaxLength) {
      const size_t cut = line.rfind(' ', kMaxLength - 4);
      line = line.substr(0, cut == std::string::npos ? kMaxLength - 4 : cut) + " ...";
    }
    text += "  " + info.name + std::string(width + 2 - info.name.size(), ' ') + line + "\n";
  }
  return text;
}

std::string FormatRunReport(const nlohmann::json& summary, const std::string& out_dir) {
  namespace fs = std::filesystem;
  const auto number = [&](const char* key) {
    return summary.contains(key) && summary[key].is_number() ? summary[key].get<double>() : 0.0;
  };
  std::string text = "== " + summary.value("scene", std::string("scene")) + ": " +
                     std::to_string(summary.value("steps", 0)) + " steps of " +
                     FormatNumber(1e3 * number("dt"), 4) + " ms in " +
                     FormatNumber(number("wall_time_s")) + " s\n";
  text += "   median " + FormatNumber(number("ms_per_step_median")) + " ms per step (" +
          FormatNumber(number("ms_per_frame_60hz")) + " ms per 1/60 s frame), " +
          std::to_string(summary.value("unconverged_steps", 0)) +
          " unconverged steps, max violation " + FormatNumber(number("max_violation")) + "\n";
  // The outputs present in out_dir, by kind.
  std::vector<std::string> pvd, pictures;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(out_dir, ec)) {
    const std::string ext = entry.path().extension().string();
    if (ext == ".pvd") pvd.push_back(entry.path().filename().string());
    if (ext == ".png" || ext == ".gif") pictures.push_back(entry.path().filename().string());
  }
  std::sort(pvd.begin(), pvd.end());
  std::sort(pictures.begin(), pictures.end());
  const std::string dir = (fs::path(out_dir) / "").string();
  text +=
      "   results: " + dir + "summary.json (figures), " + dir + "steps.csv (one row per step)\n";
  if (!pictures.empty()) {
    text += "   pictures (" + std::to_string(pictures.size()) + "): " + dir + pictures.front();
    if (pictures.size() > 1) text += " ... " + pictures.back();
    text += " (any image viewer)\n";
  }
  if (!pvd.empty()) {
    text += "   VTK: " + std::to_string(pvd.size()) +
            " ParaView collection(s), open as one animation: paraview";
    if (pvd.size() <= 2) {
      for (const std::string& name : pvd) text += " " + dir + name;
    } else {
      text += " " + dir + "*.pvd (" + pvd.front() + " ... " + pvd.back() + ")";
    }
    text += "\n";
  } else {
    text += "   VTK: none (add --vtk for ParaView frames)\n";
  }
  return text;
}

}  // namespace taut
