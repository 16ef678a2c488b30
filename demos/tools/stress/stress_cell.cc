#include "demos/tools/stress/stress_cell.h"

#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "plugin/common.h"

namespace taut::stress {

const char* GetCellStatusName(CellStatus status) {
  switch (status) {
    case CellStatus::kPass:
      return "pass";
    case CellStatus::kDegrades:
      return "degrades";
    case CellStatus::kFailsLoudly:
      return "fails loudly";
    case CellStatus::kPending:
      return "pending";
    case CellStatus::kBroken:
      return "BROKEN";
  }
  return "?";
}

bool Check::failed() const { return !std::isnan(limit) && !(value <= limit); }

void CellResult::AddCheck(const std::string& check_name, double value, double limit) {
  checks.push_back({check_name, value, limit});
}

void CellResult::AddFigure(const std::string& figure_name, double value) {
  checks.push_back({figure_name, value, std::numeric_limits<double>::quiet_NaN()});
}

const Check& CellResult::check(const std::string& check_name) const {
  for (const Check& c : checks)
    if (c.name == check_name) return c;
  throw std::out_of_range("cell '" + group + " / " + name + "' has no check '" + check_name + "'");
}

void CellResult::MarkPending(const std::string& why) {
  status = CellStatus::kPending;
  note = why;
}

namespace {
// Sets status and note from the checks after the body returned normally.
void ClassifyFinishedCell(CellResult& result) {
  if (!result.finite) {
    result.status = CellStatus::kBroken;
    result.note =
        "non-finite state without an error after step " + std::to_string(result.steps_run);
    return;
  }
  std::string failed;
  for (const Check& c : result.checks)
    if (c.failed()) failed += (failed.empty() ? "" : "; ") + c.name;
  if (result.status == CellStatus::kPending) return;
  if (!failed.empty()) {
    result.status = CellStatus::kDegrades;
    result.note = failed + (result.note.empty() ? "" : " (" + result.note + ")");
  }
}
}  // namespace

CellResult RunCellGuarded(const std::string& group, const std::string& name, const CellBody& body) {
  CellResult result;
  result.group = group;
  result.name = name;
  const auto start = std::chrono::steady_clock::now();
  try {
    body(result);
    ClassifyFinishedCell(result);
  } catch (const SimulationError& e) {
    result.status = CellStatus::kFailsLoudly;
    result.note = std::string("SimulationError: ") + e.what();
  } catch (const InputError& e) {
    result.status = CellStatus::kFailsLoudly;
    result.note = std::string("InputError: ") + e.what();
  } catch (const std::exception& e) {
    result.status = CellStatus::kBroken;
    result.note = std::string("unexpected exception: ") + e.what();
  }
  result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

nlohmann::json ToJson(const CellResult& result) {
  nlohmann::json checks = nlohmann::json::array();
  // JSON has no NaN or infinity: write them as strings.
  const auto number = [](double v) {
    return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(std::to_string(v));
  };
  for (const Check& c : result.checks)
    checks.push_back({{"name", c.name}, {"value", number(c.value)}, {"limit", number(c.limit)}});
  return {{"group", result.group},
          {"name", result.name},
          {"status", static_cast<int>(result.status)},
          {"note", result.note},
          {"steps_planned", result.steps_planned},
          {"steps_run", result.steps_run},
          {"finite", result.finite},
          {"checks", checks},
          {"wall_s", result.wall_s}};
}

CellResult CellResultFromJson(const nlohmann::json& json) {
  const auto number = [](const nlohmann::json& v) {
    return v.is_string() ? std::stod(v.get<std::string>()) : v.get<double>();
  };
  CellResult result;
  result.group = json.at("group").get<std::string>();
  result.name = json.at("name").get<std::string>();
  result.status = static_cast<CellStatus>(json.at("status").get<int>());
  result.note = json.at("note").get<std::string>();
  result.steps_planned = json.at("steps_planned").get<int>();
  result.steps_run = json.at("steps_run").get<int>();
  result.finite = json.at("finite").get<bool>();
  for (const auto& c : json.at("checks"))
    result.checks.push_back(
        {c.at("name").get<std::string>(), number(c.at("value")), number(c.at("limit"))});
  result.wall_s = json.at("wall_s").get<double>();
  return result;
}

}  // namespace taut::stress
