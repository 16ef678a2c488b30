// Cube cells: drops and impacts, recovery from inverted or flat starts, slivers, long runs.
#include <algorithm>
#include <cmath>

#include "demos/scenes/scene.h"
#include "demos/tools/stress/stress_bodies.h"
#include "demos/tools/stress/stress_cells.h"
#include "demos/tools/stress/stress_monitor.h"

namespace taut::stress {

namespace {
constexpr double kDensity = 1000.0;

// Steps for a duration at step h (at least one).
int CountSteps(double duration, double h) {
  return std::max(1, static_cast<int>(std::lround(duration / h)));
}

// Vertical extent (top - bottom) of the body now [m].
double CalcHeight(const DeformableBody& body) {
  Vec3 lo, hi;
  body.CalcBounds(lo, hi);
  return hi.z() - lo.z();
}

// Inverted elements of a tet or hex body at its current positions.
int CountInvertedElements(const DeformableBody& body) {
  if (const TetMesh* mesh = body.rest_tet_mesh())
    return CalcTetVolumeStats(*mesh, body.x()).inverted;
  const HexLattice* lattice = body.rest_hex_lattice();
  TAUT_DEMAND(lattice != nullptr, "body '", body.name(), "' is neither a tet nor a hex body");
  return CountInvertedHexes(*lattice, body.x());
}
}  // namespace

void RunDropCell(const DropParams& params, CellResult& result) {
  constexpr double kSide = 0.2;
  BulletWorldHolder holder;
  holder.AddStaticGround();
  DeformableBody* cube = AddCubeBody(
      kSide, params.cells, params.hexes, Vec3(-0.5 * kSide, -0.5 * kSide, params.height),
      MakeSceneBodySettings("cube", params.youngs_modulus, kDensity), holder.world);
  VecX v = VecX::Zero(3 * cube->num_nodes());
  for (int i = 0; i < cube->num_nodes(); ++i) v[3 * i + 2] = -params.speed;
  cube->set_v(v);
  const TetMesh* tet_mesh = cube->rest_tet_mesh();
  // Surface nodes carry the contact rows (tets: boundary nodes; hexes: every node).
  std::vector<int> surface;
  if (tet_mesh != nullptr) {
    surface = CalcBoundaryNodes(*tet_mesh);
  } else {
    for (int i = 0; i < cube->num_nodes(); ++i) surface.push_back(i);
  }
  StressMonitor monitor(holder.world, 0.0);
  result.steps_planned = CountSteps(params.duration, params.h);
  bool landed = false;
  double rebound = 0.0, min_volume_ratio = 1.0, surface_penetration = 0.0;
  monitor.Run(holder.world, params.h, result.steps_planned, result, [&](int) {
    const double gap = monitor.CalcLowestGap();
    if (gap < 1e-3) landed = true;
    if (landed) rebound = std::max(rebound, gap);
    for (int i : surface)
      surface_penetration = std::max(surface_penetration, -cube->node_position(i).z());
    if (tet_mesh != nullptr)
      min_volume_ratio =
          std::min(min_volume_ratio, CalcTetVolumeStats(*tet_mesh, cube->x()).min_volume_ratio);
  });
  StandardTolerances tolerances;
  tolerances.penetration = params.penetration_tolerance;
  monitor.AddStandardChecks(result, tolerances);
  result.AddFigure("height loss / side", 1.0 - CalcHeight(*cube) / kSide);
  result.AddFigure("closed form rho g L / 2E",
                   kDensity * kGravity * kSide / (2.0 * params.youngs_modulus));
  result.AddFigure("surface node penetration [m]", surface_penetration);
  result.AddFigure("rebound [m]", rebound);
  if (tet_mesh != nullptr) result.AddFigure("min tet volume ratio", min_volume_ratio);
  result.AddFigure("inverted at end", CountInvertedElements(*cube));
}

void RunRecoveryCell(const RecoveryParams& params, CellResult& result) {
  constexpr double kSide = 0.2;
  BulletWorldHolder holder;
  holder.AddStaticGround();
  DeformableBody* cube =
      AddCubeBody(kSide, params.cells, params.hexes, Vec3(-0.5 * kSide, -0.5 * kSide, 0.0),
                  MakeSceneBodySettings("cube", 1e5, kDensity, 2.0), holder.world);
  VecX x = cube->x();
  switch (params.shape) {
    case StartShape::kMirrored:
      MirrorPositions(Vec3::Zero(), Vec3::UnitX(), x);
      break;
    case StartShape::kSquashed:
      SquashPositions(0.0, x);
      break;
    case StartShape::kNodeThrough:
      x.segment<3>(0) += 0.7 * Vec3::Constant(kSide);  // node 0 is the (-, -, 0) corner
      break;
  }
  cube->set_x(x);
  result.AddFigure("inverted at start", CountInvertedElements(*cube));
  StressMonitor monitor(holder.world, 0.0);
  result.steps_planned = CountSteps(params.duration, params.h);
  const VecX& rest = cube->model().rest_positions();
  double recovered_at = HUGE_VAL;
  monitor.Run(holder.world, params.h, result.steps_planned, result, [&](int step) {
    if (recovered_at == HUGE_VAL && CountInvertedElements(*cube) == 0 &&
        CalcShapeError(rest, cube->x(), cube->mass(), kSide) < params.shape_tolerance)
      recovered_at = (step + 1) * params.h;
  });
  monitor.AddStandardChecks(result, StandardTolerances());
  if (const TetMesh* tet_mesh = cube->rest_tet_mesh())
    result.AddCheck("|volume / rest - 1|",
                    std::abs(CalcTetVolumeStats(*tet_mesh, cube->x()).volume_ratio - 1.0),
                    params.volume_tolerance);
  result.AddCheck("inverted at end", CountInvertedElements(*cube), 0.0);
  result.AddCheck("shape error / side", CalcShapeError(rest, cube->x(), cube->mass(), kSide),
                  params.shape_tolerance);
  result.AddFigure("recovered at [s]", recovered_at);
}

void RunSliverCell(const SliverParams& params, CellResult& result) {
  constexpr double kSide = 0.2;
  BulletWorldHolder holder;
  holder.AddStaticGround();
  const SliverMesh sliver =
      MakeSliverCubeMesh(kSide, 3, params.quality, Vec3(-0.5 * kSide, -0.5 * kSide, 0.02));
  result.AddFigure("sliver tets", sliver.num_slivers);
  result.AddFigure("min quality at start", sliver.min_quality);
  DeformableBody* cube = holder.world.AddTetBody(
      sliver.mesh, MakeSceneBodySettings("sliver_cube", params.youngs_modulus, kDensity));
  if (params.strain_limit > 0.0)
    holder.world.SetStrainLimits(
        cube, StrainLimitSettings::Isotropic(1.0 - params.strain_limit, 1.0 + params.strain_limit));
  StressMonitor monitor(holder.world, 0.0);
  result.steps_planned = CountSteps(params.duration, params.h);
  double min_volume_ratio = 1.0;
  monitor.Run(holder.world, params.h, result.steps_planned, result, [&](int) {
    min_volume_ratio =
        std::min(min_volume_ratio, CalcTetVolumeStats(sliver.mesh, cube->x()).min_volume_ratio);
  });
  monitor.AddStandardChecks(result, StandardTolerances());
  result.AddFigure("min tet volume ratio", min_volume_ratio);
  result.AddCheck("inverted at end", CalcTetVolumeStats(sliver.mesh, cube->x()).inverted, 0.0);
}

void RunLongRunCell(const LongRunParams& params, CellResult& result) {
  constexpr double kSide = 0.1;
  BulletWorldHolder holder;
  holder.AddStaticGround();
  DeformableBody* cube = AddCubeBody(kSide, 2, false, Vec3(-0.5 * kSide, -0.5 * kSide, 1e-3),
                                     MakeSceneBodySettings("cube", 1e5, kDensity), holder.world);
  if (params.strain_limit > 0.0)
    holder.world.SetStrainLimits(
        cube, StrainLimitSettings::Isotropic(1.0 - params.strain_limit, 1.0 + params.strain_limit));
  const Vec3 start = CalcCentreOfMass(*cube);
  StressMonitor monitor(holder.world, 0.0);
  result.steps_planned = params.steps;
  double max_speed_late = 0.0;
  monitor.Run(holder.world, params.h, params.steps, result, [&](int step) {
    if (step >= params.steps / 2)
      for (int i = 0; i < cube->num_nodes(); ++i)
        max_speed_late = std::max(max_speed_late, cube->v().segment<3>(3 * i).norm());
  });
  monitor.AddStandardChecks(result, StandardTolerances());
  const Vec3 drift = CalcCentreOfMass(*cube) - start;
  result.AddCheck("horizontal drift [m]", drift.head<2>().norm(), 1e-3);
  const double weight_scale = cube->mass().sum() * kGravity * kSide;
  result.AddCheck("final kinetic / (m g L)", cube->CalcKineticEnergy() / weight_scale, 1e-6);
  result.AddFigure("max node speed, 2nd half [m/s]", max_speed_late);
}

}  // namespace taut::stress
