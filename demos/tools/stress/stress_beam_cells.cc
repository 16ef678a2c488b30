// Cantilever cells: stiff material at large steps, strain and energy limits, length scale.
#include <algorithm>
#include <cmath>
#include <memory>

#include "demos/scenes/scene.h"
#include "demos/tools/stress/stress_bodies.h"
#include "demos/tools/stress/stress_cells.h"
#include "demos/tools/stress/stress_monitor.h"
#include "plugin/box_tet_mesher.h"
#include "plugin/hex_lattice.h"

namespace taut::stress {

namespace {

// Euler-Bernoulli tip sag of a cantilever under its own weight q = rho g H^2:
// q L^4 / (8 E I) with I = H^4 / 12, i.e. 1.5 rho g L^4 / (E H^2) [m].
double CalcEulerBernoulliSag(double length, double height, double youngs_modulus, double density) {
  return 1.5 * density * kGravity * std::pow(length, 4) / (youngs_modulus * height * height);
}

// First bending frequency of the cantilever, 3.516 / L^2 sqrt(E I / (rho A)) [rad/s].
double CalcFirstBendingFrequency(double length, double height, double youngs_modulus,
                                 double density) {
  return 3.516 / (length * length) * height / std::sqrt(12.0) * std::sqrt(youngs_modulus / density);
}
}  // namespace

void RunBeamCell(const BeamParams& params, CellResult& result) {
  const double length = params.scale, height = 0.1 * params.scale;
  BulletWorldHolder holder;
  holder.AddStaticGround();
  DeformableBodySettings settings =
      MakeSceneBodySettings("beam", params.youngs_modulus, params.density, params.mass_damping);
  settings.contact_margin = 0.01 * params.scale;
  const Vec3 size(length, height, height), corner(0.0, -0.5 * height, 0.5 * length);
  DeformableBody* beam =
      params.hexes
          ? holder.world.AddHexBody(MakeBoxHexLattice(size, params.nx, 1, 1, corner), settings)
          : holder.world.AddTetBody(MakeBoxTetMesh(size, params.nx, 1, 1, corner), settings);
  beam->FixNodesWhere([&](const Vec3& X) { return X.x() < 1e-9 * length; });
  std::vector<int> tip;
  for (int i = 0; i < beam->num_nodes(); ++i)
    if (beam->model().rest_positions()[3 * i] > (1.0 - 1e-9) * length) tip.push_back(i);
  StrainLimitSource* strain = nullptr;
  EnergyLimitSource* energy = nullptr;
  if (params.strain_limit > 0.0)
    strain = holder.world.SetStrainLimits(
        beam, StrainLimitSettings::Isotropic(1.0 - params.strain_limit, 1.0 + params.strain_limit));
  if (params.energy_limit_strain > 0.0)
    energy = holder.world.SetEnergyLimits(
        beam, EnergyLimitSettings::EnergyDensity(0.5 * params.youngs_modulus *
                                                 std::pow(params.energy_limit_strain, 2)));
  StressMonitor monitor(holder.world, 0.0);
  result.steps_planned = params.steps;
  double strain_violation = 0.0, energy_ratio = 0.0;
  monitor.Run(holder.world, params.h, params.steps, result, [&](int) {
    if (strain != nullptr)
      strain_violation = std::max(strain_violation, strain->CalcMaxViolation(beam->x()));
    if (energy != nullptr)
      energy_ratio = std::max(energy_ratio, energy->CalcMaxEnergyRatio(beam->x()));
  });
  StandardTolerances tolerances;
  tolerances.penetration = 1e-3 * params.scale;
  monitor.AddStandardChecks(result, tolerances);
  const double sag = -CalcMeanDisplacement(*beam, tip).z();
  result.AddFigure("tip sag [m]", sag);
  result.AddFigure(
      "sag / Euler-Bernoulli",
      sag / CalcEulerBernoulliSag(length, height, params.youngs_modulus, params.density));
  if (strain != nullptr) result.AddCheck("strain limit violation", strain_violation, 1e-2);
  if (energy != nullptr) result.AddCheck("U / U_max - 1", energy_ratio - 1.0, 1e-2);
}

void RunScaleCell(double scale, double tolerance, CellResult& result) {
  // Quasi-static stepping: with h w_1 = 20 backward Euler shrinks the slowest mode's motion by
  // ~1 / (h w_1)^2 per step, so 40 steps reach the static sag at every scale.
  const auto run = [](double s, CellResult& out) {
    BeamParams params;
    params.scale = s;
    params.steps = 40;
    params.h = 20.0 / CalcFirstBendingFrequency(s, 0.1 * s, params.youngs_modulus, params.density);
    RunBeamCell(params, out);
  };
  run(scale, result);
  CellResult reference;
  run(1.0, reference);
  const double ratio =
      result.check("sag / Euler-Bernoulli").value / reference.check("sag / Euler-Bernoulli").value;
  result.AddCheck("|sag ratio vs 1 m beam - 1|", std::abs(ratio - 1.0), tolerance);
  if (!reference.finite) result.finite = false;
}

}  // namespace taut::stress
