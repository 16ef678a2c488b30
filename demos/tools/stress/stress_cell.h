// One cell of the stress suite: its outcome, the checks it was judged by, and the guard that turns
// taut's errors into a recorded "fails loudly" instead of an aborted suite.
#pragma once

#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace taut::stress {

// How a cell ended. kBroken (a silent NaN/Inf, an unexpected exception or a crash) is never
// acceptable; kFailsLoudly means taut stopped with a SimulationError/InputError naming the cause.
enum class CellStatus { kPass, kDegrades, kFailsLoudly, kPending, kBroken };

// Name of a status for the table ("pass", "degrades", ...).
const char* GetCellStatusName(CellStatus status);

// One judged quantity: the cell passes it when value <= limit (a NaN value fails). A NaN limit
// makes it a reported figure that is not judged.
struct Check {
  std::string name;  // what is measured, with its unit
  double value = 0.0;
  double limit = 0.0;
  // True when judged and value <= limit.
  bool failed() const;
};

// Everything a cell reports.
struct CellResult {
  std::string group;  // family of cells, e.g. "stiffness x step"
  std::string name;   // the cell's parameters, e.g. "E=1e9 h=1/30"
  CellStatus status = CellStatus::kPass;
  std::string note;  // error message, why pending, or which check degraded
  int steps_planned = 0;
  int steps_run = 0;
  bool finite = true;  // every position and velocity finite after every step
  std::vector<Check> checks;
  double wall_s = 0.0;

  // Appends a judged check (value <= limit passes).
  void AddCheck(const std::string& check_name, double value, double limit);
  // Appends a reported figure that is not judged.
  void AddFigure(const std::string& figure_name, double value);
  // The check or figure with this name; throws std::out_of_range when missing.
  const Check& check(const std::string& check_name) const;
  // Marks the cell pending (a capability taut does not have yet), with the reason.
  void MarkPending(const std::string& why);
};

// A cell body: builds its scenario, runs it, fills steps and checks of `result`.
using CellBody = std::function<void(CellResult& result)>;

// Runs `body` and classifies the result: a taut::SimulationError or taut::InputError becomes
// kFailsLoudly with its message; any other exception or a non-finite state that did not throw
// becomes kBroken; a failed check becomes kDegrades naming the checks; otherwise kPass (or the
// kPending the body set). Measures wall time.
CellResult RunCellGuarded(const std::string& group, const std::string& name, const CellBody& body);

// Round trip through JSON (the suite runs each cell in a child process).
nlohmann::json ToJson(const CellResult& result);
CellResult CellResultFromJson(const nlohmann::json& json);

}  // namespace taut::stress
