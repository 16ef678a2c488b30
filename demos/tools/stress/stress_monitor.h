// Per-step watch over a stress scenario: finiteness, total energy, limit violation, penetration.
#pragma once

#include <functional>

#include "bullet_bridge/deformable_world.h"
#include "demos/tools/stress/stress_cell.h"

namespace taut::stress {

// Tolerances of the checks every cell gets.
struct StandardTolerances {
  double energy_growth = 0.01;  // (max_t E(t) - E(0)) / |E(0)| [-]; no work enters any cell
  double violation = 1e-2;      // max over steps of StepStats::violation_after [C units]
  double penetration = 1e-3;    // deepest node below the ground [m]
};

// Steps a world and records, after every step: whether every deformable x and v is finite, the
// total energy E = sum over deformables (1/2 v^T M v + U_el + sum_i m_i g_down z_i) + sum over
// dynamic rigid bodies (1/2 m |v|^2 + 1/2 w^T I w + m g_down z), the step's violation_after and
// converged flag, and the lowest deformable node relative to the ground plane z = ground_z.
// Potential energy is measured from the ground, so E(0) > 0 whenever gravity is on.
class StressMonitor {
 public:
  StressMonitor(const DeformableWorld& world, double ground_z);

  // Steps `world` (the watched one) `steps` times by h (one Bullet substep each), recording after
  // each and calling after_step(step) if given. Stops at the first non-finite state (sets
  // result.finite = false). Keeps result.steps_run current; a SimulationError or InputError is
  // rethrown with the step number in front of its message.
  void Run(DeformableWorld& world, double h, int steps, CellResult& result,
           const std::function<void(int)>& after_step = nullptr);
  // Appends the energy, violation and penetration checks and the unconverged-step count.
  void AddStandardChecks(CellResult& result, const StandardTolerances& tolerances) const;

  // Total energy of the watched world now [J].
  double CalcTotalEnergy() const;
  // Lowest deformable node z minus ground_z now [m].
  double CalcLowestGap() const;

  double initial_energy() const { return initial_energy_; }
  double max_energy() const { return max_energy_; }
  double final_energy() const { return final_energy_; }
  double max_violation() const { return max_violation_; }
  double max_penetration() const { return max_penetration_; }
  int unconverged_steps() const { return unconverged_steps_; }
  // Relative energy growth (max_t E(t) - E(0)) / |E(0)| (0 if E(0) = 0 and E never grew).
  double CalcEnergyGrowth() const;

 private:
  // True when every deformable position and velocity is finite.
  bool IsStateFinite() const;
  // Updates the maxima after a step.
  void Record();

  const DeformableWorld& world_;
  double ground_z_;
  double initial_energy_ = 0.0;
  double max_energy_ = 0.0;
  double final_energy_ = 0.0;
  double max_violation_ = 0.0;
  double max_penetration_ = 0.0;
  int unconverged_steps_ = 0;
};

}  // namespace taut::stress
