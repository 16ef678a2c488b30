// The stress suite's Markdown report (docs/stress.md) and its one-line console summary per cell.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "demos/tools/stress/stress_cell.h"

namespace taut::stress {

// What the report says about the run itself.
struct ReportInfo {
  std::string command;     // how the report was made
  std::string build_type;  // e.g. "Release"
  std::string machine;     // CPU and cores, may be empty
  double wall_s = 0.0;     // whole suite
};

// One line for the console: status, group / name, every check and figure, note.
std::string FormatCellLine(const CellResult& result);

// Writes the report: a summary count per status, one table per group (result, steps, energy
// growth, violation, penetration, the cell's own checks and figures, wall time), then the cells
// that do not pass with their notes.
void WriteMarkdownReport(const std::vector<CellResult>& results, const ReportInfo& info,
                         std::ostream& out);

}  // namespace taut::stress
