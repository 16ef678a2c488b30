// The quick cells of the stress suite (demos/tools/stress, full run: scripts/run_stress.sh):
// small meshes and few steps, each asserting the physics the cell is about.
//
// The cell sources are compiled into this test directly: the suite is a tool (taut-stress),
// not a library the test binary could link.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "demos/tools/stress/stress_beam_cells.cc"
#include "demos/tools/stress/stress_bodies.cc"
#include "demos/tools/stress/stress_cell.cc"
#include "demos/tools/stress/stress_cube_cells.cc"
#include "demos/tools/stress/stress_monitor.cc"
#include "demos/tools/stress/stress_motion_cells.cc"

namespace taut::stress {
namespace {

// Runs a cell through the same guard as the suite and prints its checks.
CellResult RunCell(const std::string& name, const CellBody& body) {
  CellResult result = RunCellGuarded("test", name, body);
  std::printf("%s: %s (%d/%d steps, %.2f s) %s\n", name.c_str(), GetCellStatusName(result.status),
              result.steps_run, result.steps_planned, result.wall_s, result.note.c_str());
  for (const Check& c : result.checks)
    std::printf("  %-48s %12.4g  limit %g\n", c.name.c_str(), c.value, c.limit);
  return result;
}

// Value of a check or figure.
double Value(const CellResult& result, const std::string& name) { return result.check(name).value; }

// The guard: taut's errors fail loudly with their message; a silent NaN or a foreign exception is
// BROKEN; a failed check degrades and is named; a NaN limit is only a figure.
TEST(StressCellTest, GuardClassifiesOutcomes) {
  const CellResult loud = RunCellGuarded("g", "loud", [](CellResult&) {
    throw SimulationError("body 'b': non-finite velocity at node 3");
  });
  EXPECT_EQ(loud.status, CellStatus::kFailsLoudly);
  EXPECT_NE(loud.note.find("node 3"), std::string::npos);
  const CellResult silent = RunCellGuarded("g", "silent", [](CellResult& r) { r.finite = false; });
  EXPECT_EQ(silent.status, CellStatus::kBroken);
  const CellResult foreign =
      RunCellGuarded("g", "foreign", [](CellResult&) { throw std::logic_error("oops"); });
  EXPECT_EQ(foreign.status, CellStatus::kBroken);
  const CellResult degraded = RunCellGuarded("g", "degraded", [](CellResult& r) {
    r.AddCheck("drift", 2.0, 1.0);
    r.AddCheck("nan", std::nan(""), 1.0);
    r.AddFigure("figure", 1e9);
  });
  EXPECT_EQ(degraded.status, CellStatus::kDegrades);
  EXPECT_EQ(degraded.note, "drift; nan");
  const CellResult fine =
      RunCellGuarded("g", "fine", [](CellResult& r) { r.AddCheck("drift", 1.0, 1.0); });
  EXPECT_EQ(fine.status, CellStatus::kPass);
  const CellResult back = CellResultFromJson(ToJson(degraded));
  EXPECT_EQ(back.status, CellStatus::kDegrades);
  EXPECT_TRUE(std::isnan(back.check("nan").value));
  EXPECT_TRUE(std::isnan(back.check("figure").limit));
}

// The shape measure ignores rigid motion and sees a mirror image; the sliver generator hits its
// target quality with a valid mesh.
TEST(StressCellTest, ShapeMeasuresAndSliverMesh) {
  BulletWorldHolder holder;
  DeformableBody* cube = AddCubeBody(0.2, 2, false, Vec3::Zero(),
                                     MakeSceneBodySettings("cube", 1e5, 1000.0), holder.world);
  const VecX& rest = cube->model().rest_positions();
  VecX moved = rest;
  const Mat3 R = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  for (int i = 0; i < cube->num_nodes(); ++i)
    moved.segment<3>(3 * i) = R * rest.segment<3>(3 * i) + Vec3(0.3, -1.0, 2.0);
  EXPECT_LT(CalcShapeError(rest, moved, cube->mass(), 0.2), 1e-12);
  VecX mirrored = rest;
  MirrorPositions(Vec3(0.1, 0.0, 0.0), Vec3::UnitX(), mirrored);
  EXPECT_GT(CalcShapeError(rest, mirrored, cube->mass(), 0.2), 0.1);
  const auto& tets = dynamic_cast<const TetElementModel&>(cube->model());
  EXPECT_EQ(CalcTetVolumeStats(tets.mesh(), mirrored).inverted, 48);
  EXPECT_NEAR(CalcTetVolumeStats(tets.mesh(), mirrored).volume_ratio, -1.0, 1e-12);

  const SliverMesh sliver = MakeSliverCubeMesh(0.2, 3, 1e-6, Vec3::Zero());
  EXPECT_NEAR(sliver.min_quality, 1e-6, 1e-9);
  EXPECT_GE(sliver.num_slivers, 1);
  EXPECT_NO_THROW(ValidateTetMesh(sliver.mesh));
}

// A cube mirrored through a plane (every tet inverted, s_3 = -1 in the signed SVD), squashed flat,
// or with a corner node pushed through it returns to its rest shape and volume within 2 %.
TEST(StressCellTest, DeformedStartsRecoverTheirRestShape) {
  for (StartShape shape : {StartShape::kMirrored, StartShape::kSquashed, StartShape::kNodeThrough})
    for (bool hexes : {false, true}) {
      RecoveryParams params;
      params.shape = shape;
      params.hexes = hexes;
      params.duration = 0.5;
      const CellResult r =
          RunCell("recovery", [&](CellResult& out) { RunRecoveryCell(params, out); });
      EXPECT_EQ(r.status, CellStatus::kPass) << r.note;
      EXPECT_GT(Value(r, "inverted at start"), 0.0);
      EXPECT_EQ(Value(r, "inverted at end"), 0.0);
      EXPECT_LT(Value(r, "shape error / side"), 0.02);
      if (!hexes) EXPECT_LT(Value(r, "|volume / rest - 1|"), 0.02);
      EXPECT_LE(Value(r, "energy growth"), 0.01);  // it started with elastic energy only
    }
}

// A free, undamped spin: internal forces keep linear momentum to round-off and angular momentum
// within 1 %, and they never add kinetic energy.
TEST(StressCellTest, FreeSpinKeepsMomentum) {
  SpinParams params;
  params.omega = 30.0;
  params.duration = 0.5;
  const CellResult r = RunCell("spin 30 rad/s", [&](CellResult& out) { RunSpinCell(params, out); });
  EXPECT_LT(Value(r, "max |L - L0| / |L0|"), 0.01);
  EXPECT_LT(Value(r, "max |P - P0| / (m (v + w side))"), 1e-9);
  EXPECT_LE(Value(r, "kinetic energy kept"), 1.0);
  // At 10 rad/s (0.04 rad per step) the total energy does not grow either.
  params.omega = 10.0;
  const CellResult slow =
      RunCell("spin 10 rad/s", [&](CellResult& out) { RunSpinCell(params, out); });
  EXPECT_EQ(slow.status, CellStatus::kPass) << slow.note;
  EXPECT_LE(Value(slow, "energy growth"), 0.01);
}

// A 10 m/s impact on the ground: no node ends more than 1 mm below the ground, and the impact adds
// no energy.
TEST(StressCellTest, ImpactAt10MetresPerSecondHoldsContact) {
  for (bool hexes : {false, true}) {
    DropParams params;
    params.speed = 10.0;
    params.height = 0.05;
    params.duration = 0.25;
    params.hexes = hexes;
    const CellResult r = RunCell("impact", [&](CellResult& out) { RunDropCell(params, out); });
    EXPECT_EQ(r.status, CellStatus::kPass) << r.note;
    EXPECT_LE(Value(r, "penetration [m]"), 1e-3);
    EXPECT_LE(Value(r, "energy growth"), 0.01);
    EXPECT_GT(Value(r, "rebound [m]"), 0.0);  // it did hit the ground
  }
}

// A 1 GPa cantilever at h = 1/30 (h w_1 = 3.4): finite, no energy growth, and at rest after 1 s
// with the quasi-static sag.
TEST(StressCellTest, StiffBeamAtLargeStepIsBoundedAndStatic) {
  BeamParams params;  // E = 1e9, h = 1/30, 30 steps
  const CellResult r = RunCell("1 GPa beam", [&](CellResult& out) { RunBeamCell(params, out); });
  EXPECT_EQ(r.status, CellStatus::kPass) << r.note;
  EXPECT_LE(Value(r, "energy growth"), 0.01);
  const CellResult reference =
      RunCell("1 GPa beam, quasi-static", [](CellResult& out) { RunScaleCell(1.0, 0.01, out); });
  EXPECT_NEAR(Value(r, "tip sag [m]") / Value(reference, "tip sag [m]"), 1.0, 0.01);
}

// The same beam from 1 mm to 10 m: the gravity sag scales as the length squared.
TEST(StressCellTest, SagScalesWithLengthSquared) {
  for (double scale : {1e-3, 10.0}) {
    const CellResult r = RunCell("scale", [&](CellResult& out) { RunScaleCell(scale, 0.01, out); });
    EXPECT_EQ(r.status, CellStatus::kPass) << r.note;
    EXPECT_LT(Value(r, "|sag ratio vs 1 m beam - 1|"), 0.01);
  }
}

// A mesh with tets of quality 1e-6 drops and lands like any other; one below the mesh check
// (1e-13) is refused with an InputError naming the element.
TEST(StressCellTest, SliversStayFiniteOrAreRefusedLoudly) {
  SliverParams params;
  params.quality = 1e-6;
  params.duration = 0.25;
  const CellResult r = RunCell("sliver 1e-6", [&](CellResult& out) { RunSliverCell(params, out); });
  EXPECT_EQ(r.status, CellStatus::kPass) << r.note;
  EXPECT_EQ(Value(r, "inverted at end"), 0.0);
  params.quality = 1e-13;
  const CellResult refused =
      RunCell("sliver 1e-13", [&](CellResult& out) { RunSliverCell(params, out); });
  EXPECT_EQ(refused.status, CellStatus::kFailsLoudly);
  EXPECT_NE(refused.note.find("element"), std::string::npos);
}

// The same cube with +-5 % strain limits on its slivers (V/l^3 = 1e-6) lands and stays on the
// ground. The sliver's rows hold only in a tiny neighbourhood, so dual steps stall from v* with
// the contacts unresolved: the cube sank 6 cm in 20 such steps and a retry then threw it up at
// 11 m/s (energy growth 60x). After such a stall the island takes the primal path.
TEST(StressCellTest, LimitedSliversKeepTheirContactsAndEnergy) {
  SliverParams params;
  params.quality = 1e-6;
  params.strain_limit = 0.05;
  params.duration = 0.2;  // landing at step 14, the stalls from step 15
  const CellResult r =
      RunCell("sliver 1e-6 +-5 %", [&](CellResult& out) { RunSliverCell(params, out); });
  EXPECT_LE(Value(r, "energy growth"), 0.01);
  EXPECT_LE(Value(r, "penetration [m]"), 2e-3);
  EXPECT_EQ(Value(r, "inverted at end"), 0.0);
}

// Strain limits of +-10 % and energy limits at eps = 0.1 on a soft sagging cantilever hold to 1 %
// of the limit.
TEST(StressCellTest, ModerateLimitsHold) {
  BeamParams params;
  params.scale = 0.5;
  params.youngs_modulus = 1e5;
  params.h = 1.0 / 240.0;
  params.steps = 60;
  params.strain_limit = 0.1;
  const CellResult strain =
      RunCell("strain +-10 %", [&](CellResult& out) { RunBeamCell(params, out); });
  EXPECT_EQ(strain.status, CellStatus::kPass) << strain.note;
  EXPECT_LE(Value(strain, "strain limit violation"), 1e-2);
  params.strain_limit = 0.0;
  params.energy_limit_strain = 0.1;
  const CellResult energy =
      RunCell("energy eps = 0.1", [&](CellResult& out) { RunBeamCell(params, out); });
  EXPECT_EQ(energy.status, CellStatus::kPass) << energy.note;
  EXPECT_LE(Value(energy, "U / U_max - 1"), 1e-2);
}

// A dynamic box 1000 times heavier than the soft slab under it rests on it: the slab compresses
// as the closed forms say, no slab node enters the box, the box does not tip.
TEST(StressCellTest, HeavyRigidBoxRestsOnSoftSlab) {
  MassRatioParams params;
  params.duration = 0.5;
  const CellResult r = RunCell("1000:1", [&](CellResult& out) { RunMassRatioCell(params, out); });
  EXPECT_EQ(r.status, CellStatus::kPass) << r.note;
  EXPECT_LE(Value(r, "compression outside [confined, free] closed forms, relative"), 0.1);
  EXPECT_LE(Value(r, "slab node inside the box, max [m]"), 1e-3);
}

}  // namespace
}  // namespace taut::stress
