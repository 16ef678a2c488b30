// Motion cells: a fast free spin (momentum conservation) and a heavy rigid box on a soft slab.
#include <algorithm>
#include <cmath>

#include "demos/scenes/scene.h"
#include "demos/tools/stress/stress_bodies.h"
#include "demos/tools/stress/stress_cells.h"
#include "demos/tools/stress/stress_monitor.h"
#include "plugin/box_tet_mesher.h"

namespace taut::stress {

void RunSpinCell(const SpinParams& params, CellResult& result) {
  constexpr double kSide = 0.2;
  BulletWorldHolder holder;
  holder.AddStaticGround();
  holder.world.setGravity(btVector3(0, 0, 0));
  DeformableBody* cube =
      AddCubeBody(kSide, 2, false, Vec3(-0.5 * kSide, -0.5 * kSide, 1.0),
                  MakeSceneBodySettings("spinner", params.youngs_modulus, 1000.0), holder.world);
  const Vec3 drift_velocity(0.3, 0.0, 0.0);
  SetRigidVelocity(drift_velocity, params.omega * Vec3(1.0, 2.0, 3.0).normalized(), *cube);
  const Vec3 L0 = CalcAngularMomentum(*cube), P0 = CalcLinearMomentum(*cube);
  const double kinetic0 = cube->CalcKineticEnergy();
  const double mass = cube->mass().sum();
  // Momentum scale of the linear check: m (|v_c| + w side).
  const double p_scale = mass * (drift_velocity.norm() + params.omega * kSide);
  StressMonitor monitor(holder.world, 0.0);
  result.steps_planned = static_cast<int>(std::lround(params.duration / params.h));
  double L_drift = 0.0, P_drift = 0.0;
  monitor.Run(holder.world, params.h, result.steps_planned, result, [&](int) {
    L_drift = std::max(L_drift, (CalcAngularMomentum(*cube) - L0).norm() / L0.norm());
    P_drift = std::max(P_drift, (CalcLinearMomentum(*cube) - P0).norm() / p_scale);
  });
  monitor.AddStandardChecks(result, StandardTolerances());
  result.AddCheck("max |L - L0| / |L0|", L_drift, params.momentum_tolerance);
  result.AddCheck("max |P - P0| / (m (v + w side))", P_drift, 1e-9);
  result.AddFigure("kinetic energy kept", cube->CalcKineticEnergy() / kinetic0);
  result.AddFigure("rotation per step [rad]", params.omega * params.h);
  const TetMesh* mesh = cube->rest_tet_mesh();
  TAUT_DEMAND(mesh != nullptr, "spin cell: the spinner must be a tet body");
  result.AddFigure("volume / rest at end", CalcTetVolumeStats(*mesh, cube->x()).volume_ratio);
}

void RunMassRatioCell(const MassRatioParams& params, CellResult& result) {
  constexpr double kSlabSide = 0.4, kSlabThickness = 0.1, kSlabDensity = 100.0;
  constexpr double kStrain = 0.05, kNu = 0.3;
  const Vec3 box_half(0.6 * kSlabSide, 0.6 * kSlabSide, 0.1);  // overhangs the slab's top face
  BulletWorldHolder holder;
  holder.AddStaticGround(params.friction);
  const double slab_mass = kSlabDensity * kSlabSide * kSlabSide * kSlabThickness;
  const double box_mass = params.ratio * slab_mass;
  const double area = kSlabSide * kSlabSide;
  // E such that the box's weight strains the slab by kStrain: m g / (A E) = kStrain.
  const double youngs_modulus = box_mass * kGravity / (area * kStrain);
  DeformableBody* slab =
      holder.world.AddTetBody(MakeBoxTetMesh(Vec3(kSlabSide, kSlabSide, kSlabThickness), 4, 4, 1,
                                             Vec3(-0.5 * kSlabSide, -0.5 * kSlabSide, 0.0)),
                              MakeSceneBodySettings("slab", youngs_modulus, kSlabDensity, 1.0));
  std::vector<int> top;
  for (int i = 0; i < slab->num_nodes(); ++i)
    if (slab->model().rest_positions()[3 * i + 2] > 0.5 * kSlabThickness) top.push_back(i);
  btRigidBody* box = AddDynamicBox(box_half, box_mass,
                                   Vec3(0.0, 0.0, kSlabThickness + box_half.z() + 1e-3), holder);
  box->setFriction(params.friction);
  // Deepest top node inside the box, measured in the box's frame [m].
  const auto box_overlap = [&] {
    const btTransform to_box = box->getWorldTransform().inverse();
    double overlap = 0.0;
    for (int i : top) {
      const Vec3 p = slab->node_position(i);
      const btVector3 local = to_box * btVector3(p.x(), p.y(), p.z());
      if (std::abs(local.x()) < box_half.x() && std::abs(local.y()) < box_half.y())
        overlap = std::max(overlap, local.z() + box_half.z());
    }
    return overlap;
  };
  StressMonitor monitor(holder.world, 0.0);
  result.steps_planned = static_cast<int>(std::lround(params.duration / params.h));
  double lowest_box = HUGE_VAL, max_overlap = 0.0, tilt = 0.0, compression_sum = 0.0;
  int samples = 0;
  monitor.Run(holder.world, params.h, result.steps_planned, result, [&](int step) {
    lowest_box = std::min(lowest_box, box->getCenterOfMassPosition().z() - box_half.z());
    max_overlap = std::max(max_overlap, box_overlap());
    tilt = std::max(tilt, static_cast<double>(box->getOrientation().getAngleShortestPath()));
    if (2 * step >= result.steps_planned) {  // mean over the second half (the box oscillates)
      compression_sum -= CalcMeanDisplacement(*slab, top).z() / kSlabThickness;
      ++samples;
    }
  });
  monitor.AddStandardChecks(result, StandardTolerances());
  result.AddFigure("box bottom, lowest [m]", lowest_box);
  result.AddCheck("box tilt, max [rad]", tilt, 0.01);
  if (lowest_box < 0.5 * kSlabThickness) {
    // Upright and still sinking: the slab does not hold the box at all (no two-way coupling).
    if (tilt < 0.05) {
      result.MarkPending(
          internal::Concat("the ", box_mass, " kg box fell through the ", slab_mass,
                           " kg slab (box bottom down to z = ", lowest_box,
                           " m): dynamic rigid bodies do not feel deformables (two-way coupling)"));
      return;
    }
    result.AddCheck("box left the slab (bottom below half its thickness)", 1.0, 0.0);
    result.note =
        internal::Concat("the box tipped over (tilt up to ", tilt, " rad) and fell off the slab");
    return;
  }
  // Mean strain under the box weight plus half the slab's own: free sides (uniaxial stress,
  // modulus E) or sides held by friction (uniaxial strain, M = E (1 - nu) / ((1 + nu)(1 - 2 nu))).
  const double free = kStrain * (1.0 + 0.5 / params.ratio);
  const double confined = free * (1.0 + kNu) * (1.0 - 2.0 * kNu) / (1.0 - kNu);
  const double compression = compression_sum / std::max(samples, 1);
  result.AddFigure("mean compression, 2nd half", compression);
  result.AddCheck("compression outside [confined, free] closed forms, relative",
                  std::max({0.0, confined - compression, compression - free}) / free, 0.1);
  result.AddCheck("slab node inside the box, max [m]", max_overlap, 1e-3);
}

}  // namespace taut::stress
