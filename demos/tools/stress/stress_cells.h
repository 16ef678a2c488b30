// The stress cells: small self-contained scenarios on a static ground plane z = 0 (gravity
// -9.81 z unless stated), each filling a CellResult with the standard checks (StressMonitor) and
// its own. Every length default below is in metres, every time in seconds.
#pragma once

#include "demos/tools/stress/stress_cell.h"

namespace taut::stress {

// Gravity of every cell that has gravity [m/s^2], along -z.
inline constexpr double kGravity = 9.81;

// A 0.2 m cube (rho = 1000, nu = 0.3) of cells^3 Kuhn-split tets (or hexes) released `height`
// above the ground with downward `speed`. Figures: final height loss relative to the rest height
// and the closed-form self-weight value rho g L / (2E), deepest surface node (contact rows act on
// surface nodes; the penetration column counts interior nodes too), rebound, smallest tet volume
// ratio.
struct DropParams {
  double youngs_modulus = 1e5;  // [Pa]
  double h = 1.0 / 240.0;
  double duration = 1.0;
  double speed = 0.0;    // initial downward speed [m/s]
  double height = 0.02;  // lowest node above the ground at t = 0
  int cells = 2;         // per side
  bool hexes = false;
  double penetration_tolerance = 1e-3;
};
void RunDropCell(const DropParams& params, CellResult& result);

// How a recovery cell's body starts (at rest, on the ground, gravity on).
enum class StartShape {
  kMirrored,     // positions mirrored through the vertical plane x = centre: every element inverted
  kSquashed,     // every z set to the ground height: every element flat
  kNodeThrough,  // one corner node pushed through the body to 70 % of the diagonal
};
// A 0.2 m cube (E = 1e5) starting deformed; it must return to its rest shape. Checks: rest volume
// within volume_tolerance, no inverted element, shape error (Kabsch RMS / side) within
// shape_tolerance at the end.
struct RecoveryParams {
  StartShape shape = StartShape::kMirrored;
  double h = 1.0 / 240.0;
  double duration = 1.5;
  int cells = 2;
  bool hexes = false;
  double volume_tolerance = 0.02;
  double shape_tolerance = 0.02;
};
void RunRecoveryCell(const RecoveryParams& params, CellResult& result);

// A 0.2 m cube of 3^3 cells with one interior node moved until its flattest tets have quality
// V / l_max^3 = quality, dropped 0.02 m, optionally with isotropic strain limits +-strain_limit.
struct SliverParams {
  double quality = 1e-6;
  double strain_limit = 0.0;  // 0: no limits
  double youngs_modulus = 1e5;
  double h = 1.0 / 240.0;
  double duration = 0.5;
};
void RunSliverCell(const SliverParams& params, CellResult& result);

// A cantilever L x H x H (L = 1 m x scale, H = L / 10) clamped at x = 0, its bottom 0.5 L above
// the ground, sagging under gravity, optionally with isotropic strain limits +-strain_limit or
// energy limits U_max = 1/2 E eps^2 per unit rest volume (eps = energy_limit_strain).
// Figure: tip sag over Euler-Bernoulli's 1.5 rho g L^4 / (E H^2) (coarse linear tets lock, so
// below 1).
struct BeamParams {
  double scale = 1.0;
  double youngs_modulus = 1e9;
  double density = 1000.0;
  double h = 1.0 / 30.0;
  int steps = 30;
  int nx = 10;  // cells along the beam (1 across)
  double strain_limit = 0.0;
  double energy_limit_strain = 0.0;
  double mass_damping = 0.0;
  bool hexes = false;  // hex lattice instead of tets (strain limits need tets)
};
void RunBeamCell(const BeamParams& params, CellResult& result);

// The beam of RunBeamCell at `scale` and at scale 1, both stepped quasi-statically (h = 20 / w_1
// for the beam's first bending frequency w_1, 40 steps): the sag must scale as scale^2, i.e. the
// sag over Euler-Bernoulli must agree between the two within `tolerance`.
void RunScaleCell(double scale, double tolerance, CellResult& result);

// A free 0.2 m cube (2^3 cells, no gravity, no damping) spun at `omega` rad/s about a generic
// axis while drifting at 0.3 m/s. Checks: angular momentum about the centre of mass within
// momentum_tolerance of its start value at every step; linear momentum within 1e-9.
struct SpinParams {
  double omega = 30.0;
  double youngs_modulus = 1e6;
  double h = 1.0 / 240.0;
  double duration = 1.0;
  double momentum_tolerance = 0.01;
};
void RunSpinCell(const SpinParams& params, CellResult& result);

// A dynamic rigid box `ratio` times heavier than the soft slab it starts on (slab 0.4 x 0.4 x
// 0.1 m, 4 x 4 x 1 cells, rho = 100, E chosen so the box's weight strains it 5 %; the box
// overhangs the slab's top face). Pending when the box sinks through the slab upright (no two-way
// coupling); degrades when it tips over and falls off. Checks: the slab's mean compression over
// the second half lies between the closed forms for free and friction-confined sides (within
// 10 %), no slab node more than 1 mm inside the box, box tilt below 0.01 rad.
struct MassRatioParams {
  double ratio = 1000.0;
  double friction = 0.5;  // ground and box Coulomb coefficient (the slab's is 0.5 times it)
  double h = 1.0 / 240.0;
  double duration = 1.0;
};
void RunMassRatioCell(const MassRatioParams& params, CellResult& result);

// A 0.1 m cube of 2^3 cells (E = 1e5) resting on the ground with isotropic strain limits
// +-strain_limit for `steps` steps. Checks: horizontal drift of the centre of mass within 1 mm,
// final kinetic energy within 1e-6 of m g side.
struct LongRunParams {
  int steps = 100000;
  double h = 1.0 / 240.0;
  double strain_limit = 0.05;
};
void RunLongRunCell(const LongRunParams& params, CellResult& result);

}  // namespace taut::stress
