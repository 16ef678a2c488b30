#include "constraints/sqp_solver.h"

#include <gtest/gtest.h>

#include "demos/scenes/bullet_world_holder.h"
#include "plugin/box_tet_mesher.h"
#include "plugin/hex_lattice.h"
#include "plugin/surface_mesh.h"

namespace taut {
namespace {

// A soft cube hanging from its top face, pulled down by a heavy load on its bottom nodes.
struct PulledCube {
  BulletWorldHolder holder;
  DeformableBody* body = nullptr;
  std::vector<int> bottom;

  explicit PulledCube(double youngs_modulus) {
    DeformableBodySettings settings;
    settings.name = "cube";
    settings.material = {youngs_modulus, 0.3, 1000.0};
    settings.mass_damping = 2.0;
    body = holder.world.AddTetBody(MakeBoxTetMesh(Vec3(0.1, 0.1, 0.1), 2, 2, 2), settings);
    body->FixNodesWhere([](const Vec3& X) { return X.z() > 0.1 - 1e-9; });
    for (int i = 0; i < body->num_nodes(); ++i)
      if (body->model().rest_positions()[3 * i + 2] < 1e-9) bottom.push_back(i);
  }
  // Steps with a downward load on the bottom nodes; returns the largest vertical stretch seen.
  void Run(int steps, double load) {
    for (int step = 0; step < steps; ++step) {
      for (int i : bottom) body->AddNodeForce(i, Vec3(0, 0, -load));
      holder.world.stepSimulation(1.0 / 240.0, 1, 1.0 / 240.0);
    }
  }
  // Current height of the cube (top face fixed at z = 0.1).
  double Height() const {
    double z = 0.0;
    for (int i : bottom) z += body->node_position(i).z();
    return 0.1 - z / static_cast<double>(bottom.size());
  }
};

TEST(SqpSolverTest, IsotropicLimitHoldsWhereTheUnlimitedBodyStretchesFar) {
  PulledCube free_cube(2e3), limited(2e3);
  limited.holder.world.SetStrainLimits(limited.body, StrainLimitSettings::Isotropic(0.9, 1.1));
  free_cube.Run(240, 2.0);
  limited.Run(240, 2.0);
  // Unlimited: stretched far past 10 %; limited: within the limit (solver tolerance).
  EXPECT_GT(free_cube.Height(), 0.1 * 1.2);
  EXPECT_LT(limited.Height(), 0.1 * 1.1 * 1.01);
  EXPECT_GT(limited.Height(), 0.1 * 1.03);
  const StepStats& stats = limited.holder.world.last_step_stats();
  EXPECT_GT(stats.rows_strain, 0);
  EXPECT_GE(stats.sqp_iterations, 0);
  EXPECT_LE(stats.violation_after, 0.05);
  EXPECT_TRUE(limited.body->x().allFinite());
}

TEST(SqpSolverTest, EnergyLimitThroughTheWorldCapsEveryElement) {
  PulledCube free_cube(2e3), limited(2e3);
  EnergyLimitSource* limit =
      limited.holder.world.SetEnergyLimits(limited.body, EnergyLimitSettings::EnergyDensity(20.0));
  free_cube.Run(120, 2.0);
  double worst = 0.0;
  for (int step = 0; step < 120; ++step) {
    limited.Run(1, 2.0);
    worst = std::max(worst, limit->CalcMaxEnergyRatio(limited.body->x()));
  }
  EXPECT_LE(worst, 1.01);
  EXPECT_GT(limited.holder.world.last_step_stats().rows_energy, 0);
  EXPECT_GT(free_cube.Height() - 0.1, 2.0 * (limited.Height() - 0.1));
}

TEST(SqpSolverTest, TightOnePercentLimitOnOneKilopascalBodyHolds2000Steps) {
  // A 1 kPa bar hanging from one end strains ~50 % unlimited; +-1 % must hold, with no NaN.
  BulletWorldHolder holder;
  DeformableBodySettings settings;
  settings.material = {1e3, 0.3, 1000.0};
  settings.mass_damping = 1.0;
  DeformableBody* body =
      holder.world.AddTetBody(MakeBoxTetMesh(Vec3(0.15, 0.05, 0.05), 3, 1, 1), settings);
  body->FixNodesWhere([](const Vec3& X) { return X.x() < 1e-9; });
  StrainLimitSource* limit =
      holder.world.SetStrainLimits(body, StrainLimitSettings::Isotropic(0.99, 1.01));
  double worst = 0.0;
  int unconverged = 0;
  for (int step = 0; step < 2000; ++step) {
    holder.world.stepSimulation(1.0 / 240.0, 1, 1.0 / 240.0);
    ASSERT_TRUE(body->x().allFinite()) << "step " << step;
    worst = std::max(worst, limit->CalcMaxViolation(body->x()));
    unconverged += holder.world.last_step_stats().converged ? 0 : 1;
  }
  std::printf(
      "1 %% limit, 2000 steps: worst violation %.2e (fraction of the limit), %d "
      "unconverged steps\n",
      worst, unconverged);
  EXPECT_LE(worst, 2e-3);
  EXPECT_EQ(unconverged, 0);
}

TEST(SqpSolverTest, NoActiveRowsMeansNoLcp) {
  // A body at rest with wide limits: no row is within the margin, so no PGS runs at all.
  PulledCube cube(1e6);
  cube.holder.world.SetStrainLimits(cube.body, StrainLimitSettings::Isotropic(0.5, 1.5));
  cube.Run(10, 0.0);
  const StepStats& stats = cube.holder.world.last_step_stats();
  EXPECT_EQ(stats.rows_strain, 0);
  EXPECT_EQ(stats.pgs_sweeps, 0);
  EXPECT_EQ(stats.sqp_iterations, 0);
}

TEST(SqpSolverTest, OrthogonalProjectionFreezesTheVerticalColumn) {
  // Paper A §5: with orthogonal projection every deformation violates (docs/math.md §6 A1), so a
  // compliant column fixed at its bottom barely moves, while hyperbolic lets it sag.
  auto top_drop = [](StrainProjection mode) {
    BulletWorldHolder holder;
    DeformableBodySettings settings;
    settings.material = {10e3, 0.3, 1000.0};
    settings.mass_damping = 1.0;
    DeformableBody* body =
        holder.world.AddTetBody(MakeBoxTetMesh(Vec3(0.2, 0.2, 1.0), 1, 1, 4), settings);
    body->FixNodesWhere([](const Vec3& X) { return X.z() < 1e-9; });
    const double free = kUnlimitedStretch;
    holder.world.SetStrainLimits(
        body, StrainLimitSettings::PerAxis(Vec3(0.95, 0, 0), Vec3(1.05, free, free), mode));
    for (int step = 0; step < 40; ++step) holder.world.stepSimulation(1.0 / 240, 1, 1.0 / 240);
    double drop = 0.0;
    for (int i = 0; i < body->num_nodes(); ++i)
      drop = std::max(drop, body->model().rest_positions()[3 * i + 2] - body->node_position(i).z());
    return drop;
  };
  const double orthogonal = top_drop(StrainProjection::kOrthogonal);
  const double hyperbolic = top_drop(StrainProjection::kHyperbolic);
  std::printf("column top drop after 1/6 s: orthogonal %.4f m, hyperbolic %.4f m\n", orthogonal,
              hyperbolic);
  EXPECT_GT(hyperbolic, 0.02);
  EXPECT_LT(orthogonal, 0.3 * hyperbolic);
}

TEST(SqpSolverTest, QpPgsToleranceHoldsTheWarmStopsDistanceAtLargeSteps) {
  const SqpSettings settings;
  // Cold starts and small steps keep the PGS tolerance; from the warm start at h the sweep's w
  // error times h stays within half the warm stop's distance, f contact_tolerance / 2.
  EXPECT_EQ(CalcQpPgsTolerance(1.0 / 60.0, false, settings), settings.pgs.tolerance);
  EXPECT_EQ(CalcQpPgsTolerance(1.0 / 240.0, true, settings), settings.pgs.tolerance);
  const double h = 1.0 / 60.0;
  EXPECT_NEAR(h * CalcQpPgsTolerance(h, true, settings),
              0.5 * settings.warm_stop_distance_factor * settings.contact_tolerance, 1e-18);
}

// A soft hex block on a coarse lattice (2 x 2 x 1 cells) touching the ground through a fine
// embedded surface (81 points under 4 cells: many coupled contact rows per cell, as the
// armadillo's), pushed sideways at h = 1/60 s on the dual path by half its weight at one top
// corner: every step from the warm start is certified after at most two QPs (measured: 1; 5
// before). With the PGS to 1e-4 1/s (a C error of h 1e-4 = 1.7e-6 m against the warm stop's 1e-6 m)
// such steps ran one PGS sweep per SQP iteration.
TEST(SqpSolverTest, BlockPushedOverTheGroundAtLargeStepsStopsAfterTwoQps) {
  BulletWorldHolder holder;
  holder.AddStaticGround(0.5);
  DeformableBodySettings settings;
  settings.name = "block";
  settings.material = {2e5, 0.3, 1000.0};
  settings.mass_damping = 1.0;
  const HexLattice lattice = MakeBoxHexLattice(Vec3(0.4, 0.4, 0.2), 2, 2, 1, Vec3(-0.2, -0.2, 0.0));
  DeformableBody* block = holder.world.AddHexBody(lattice, settings);
  holder.world.SetContactSurface(
      block, MakeBoxSurface(Vec3(0.4, 0.4, 0.2), 8, 8, 4, Vec3(-0.2, -0.2, 0.0)));
  int corner = 0;
  for (int i = 0; i < block->num_nodes(); ++i)
    if (block->node_position(i).z() > block->node_position(corner).z() - 1e-9 &&
        block->node_position(i).x() <= block->node_position(corner).x())
      corner = i;
  holder.world.mutable_solver_settings().solver = IslandSolverKind::kDual;
  const double h = 1.0 / 60.0, weight = 0.4 * 0.4 * 0.2 * 1000.0 * 9.81;
  int rows = 0, max_sqp = 0, unconverged = 0;
  for (int step = 0; step < 60; ++step) {
    if (step >= 10) block->AddNodeForce(corner, Vec3(0.5 * weight, 0.0, 0.0));
    holder.world.stepSimulation(h, 1, h);
    const StepStats& stats = holder.world.last_step_stats();
    if (step < 10) continue;  // settling on the ground
    rows = std::max(rows, stats.rows_contact);
    max_sqp = std::max(max_sqp, stats.sqp_iterations);
    unconverged += stats.converged ? 0 : 1;
  }
  std::printf(
      "contact rows %d, most SQP iterations in a step %d, unconverged %d of 50, "
      "corner x %.3f m\n",
      rows, max_sqp, unconverged, block->node_position(corner).x());
  EXPECT_GT(rows, 0);
  EXPECT_EQ(unconverged, 0);
  EXPECT_LE(max_sqp, 2);
}

}  // namespace
}  // namespace taut
