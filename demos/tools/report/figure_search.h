// Figures taut-report takes from a scene's own summary (Scene::WriteFigures): the largest energy
// ratio U_e/U_max and the deepest penetration over every body the scene lists.
//
// Header-only (inline) on purpose: tests/report_*_test.cc check this logic, and the tool's .cc
// files are linked only into taut-report, not into the test binary.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

namespace taut {

// Max of a and b where NaN means "none".
inline double MaxOfKnown(double a, double b) {
  if (std::isnan(a)) return b;
  if (std::isnan(b)) return a;
  return std::max(a, b);
}

// Largest number stored under a key accepted by `match` anywhere in `node` (objects and arrays
// are searched; null and non-numbers are skipped); NaN when there is none.
template <typename Match>
double FindMaxFigure(const nlohmann::json& node, const Match& match) {
  double best = std::numeric_limits<double>::quiet_NaN();
  if (node.is_object()) {
    for (auto it = node.begin(); it != node.end(); ++it) {
      if (it.value().is_number() && match(it.key()))
        best = MaxOfKnown(best, it.value().get<double>());
      else
        best = MaxOfKnown(best, FindMaxFigure(it.value(), match));
    }
  } else if (node.is_array()) {
    for (const nlohmann::json& item : node) best = MaxOfKnown(best, FindMaxFigure(item, match));
  }
  return best;
}

// Largest "max_energy_ratio" (U_e/U_max over the run) of any body; NaN when no body has one.
inline double FindMaxEnergyRatio(const nlohmann::json& figures) {
  return FindMaxFigure(figures, [](const std::string& key) { return key == "max_energy_ratio"; });
}

// Largest figure whose key mentions "penetration" (depth in m); NaN when there is none.
inline double FindMaxPenetration(const nlohmann::json& figures) {
  return FindMaxFigure(
      figures, [](const std::string& key) { return key.find("penetration") != std::string::npos; });
}

}  // namespace taut
