// One run of a registered scene at one sweep point, measured for taut-report.
#pragma once

#include <vector>

#include "demos/scenes/scene.h"
#include "demos/tools/report/report_table.h"
#include "demos/tools/report/sweep_plan.h"
#include "demos/tools/report/trajectory_error.h"

namespace taut {

// How long every run of a scene lasts and when it is sampled. All runs cover the same simulated
// time samples * frame_steps * dt and are sampled at the same times k * frame_steps * dt.
struct RunPlan {
  double dt = 0.0;            // scene time step at divisor 1 [s]
  int frame_steps = 1;        // steps of length dt between samples (about one 1/60 s frame)
  int samples = 1;            // samples of a full run (the last one ends the run)
  double cpu_budget_s = 0.0;  // a run stops after this much CPU time (0: no limit)
};

// The reference trajectory the sweep runs are compared against.
struct ReferenceTrajectory {
  std::vector<TrajectorySample> samples;     // (samples) free-node positions at each sample time
  std::vector<std::vector<double>> lengths;  // (samples x bodies) rest bounding-box diagonals [m]
};

// What a run measured, and its trajectory at the sample times it reached.
struct RunOutcome {
  ReportRow row;
  std::vector<TrajectorySample> samples;
  std::vector<std::vector<double>> lengths;  // (samples x bodies) rest bounding-box diagonals [m]
  int completed_samples = 0;  // sample times reached before a failure or the CPU budget
};

// Builds the scene, applies `point` (settings, dt / divisor), steps it for the plan's simulated
// time (or until the CPU budget runs out or the simulation fails, which the row's status says)
// and measures it; the trajectory error is against `reference` when given. Throws InputError
// when the scene cannot be built.
RunOutcome RunSweepPoint(const SceneInfo& info, const SweepPoint& point, const RunPlan& plan,
                         const ReferenceTrajectory* reference);

// Whether StepStats carries the natural-map residual of the step's last QP (lcp_residual).
bool StepStatsHaveLcpResidual();

// Rest bounding-box diagonal of every deformable body of a scene [m].
std::vector<double> CalcBodyLengths(const Scene& scene);

}  // namespace taut
