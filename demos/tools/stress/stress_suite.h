// The list of stress cells (full suite and a seconds-long smoke subset) and how one is run.
#pragma once

#include <string>
#include <vector>

#include "demos/tools/stress/stress_cell.h"

namespace taut::stress {

// One named cell of the suite.
struct SuiteCell {
  std::string group;
  std::string name;
  CellBody body;
};

// Every cell of the full suite, grouped, in report order.
std::vector<SuiteCell> MakeFullSuite();
// A few short cells (a smoke run of seconds).
std::vector<SuiteCell> MakeSmokeSuite();

// Runs the cell in a child process (fork) so that a crash or a hang is recorded instead of ending
// the suite: a signal becomes kBroken "crashed: signal N", running past timeout_s becomes
// kBroken "did not finish within timeout_s". isolate = false runs it in this process.
CellResult RunSuiteCell(const SuiteCell& cell, bool isolate, double timeout_s);

}  // namespace taut::stress
