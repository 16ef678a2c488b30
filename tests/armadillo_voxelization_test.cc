// The armadillo of paper B Fig. 6 (Stanford 3D Scanning Repository, from Debian's libcgal-demo;
// scripts/fetch_armadillo.sh puts it in data/): closed, and voxelized at h = 0.1145 m after
// scaling to 2 m tall it gives about the paper's 365 hexes.
#include <gtest/gtest.h>

#include <filesystem>

#include "plugin/embedded_surface.h"
#include "plugin/hex_voxelizer.h"
#include "plugin/off_reader.h"

namespace taut {
namespace {

TEST(ArmadilloVoxelizationTest, TwoMetreArmadilloGivesAboutThePapers365Hexes) {
  const std::string path = std::string(TAUT_DATA_DIR) + "/armadillo.off";
  if (!std::filesystem::exists(path))
    GTEST_SKIP() << path << " missing: run scripts/fetch_armadillo.sh";
  SurfaceMesh surface = ReadOffSurface(path);
  EXPECT_EQ(surface.vertices.size(), 26002u);
  const Eigen::AlignedBox3d bounds = CalcSurfaceBounds(surface);
  const double scale = 2.0 / bounds.sizes().y();  // y is up in the scan
  for (Vec3& v : surface.vertices) v = (v - bounds.min()) * scale;
  ValidateClosedSurface(surface);
  const HexLattice lattice = VoxelizeSurface(surface, 0.1145);
  std::printf("armadillo: %zu hexes, %zu nodes\n", lattice.hexes.size(), lattice.nodes.size());
  EXPECT_GT(lattice.hexes.size(), 340u);
  EXPECT_LT(lattice.hexes.size(), 390u);
  ValidateHexLattice(lattice);
  // Every scan vertex gets trilinear weights summing to one.
  const EmbeddedSurface embedded = EmbedSurface(lattice, surface);
  ASSERT_EQ(embedded.vertices.size(), surface.vertices.size());
  for (const EmbeddedVertex& v : embedded.vertices) {
    double sum = 0.0;
    for (double w : v.weights) sum += w;
    ASSERT_NEAR(sum, 1.0, 1e-12);
  }
}

}  // namespace
}  // namespace taut

#include "demos/scenes/armadillo_scene.h"

namespace taut {
namespace {

// Paper B Fig. 6 setting: the energy-limited armadillo lands (0.5 m drop) without sinking into
// the ground and its limit holds.
TEST(ArmadilloSceneTest, LimitedArmadilloLandsAndItsEnergyLimitHolds) {
  if (!std::filesystem::exists(std::string(TAUT_DATA_DIR) + "/armadillo.off"))
    GTEST_SKIP() << "data/armadillo.off missing: run scripts/fetch_armadillo.sh";
  ArmadilloScene scene({{"limited", 500e3, 100.0}}, std::string(TAUT_DATA_DIR) + "/armadillo.off");
  for (int step = 0; step < 120; ++step) scene.Step(1.0 / 240.0);
  std::printf("armadillo: deepest %.2e m, flattening %.3f, U/Umax %.5f, contact rows %d\n",
              scene.deepest(0), scene.max_flattening(0), scene.max_energy_ratio(0),
              scene.world().last_step_stats().rows_contact);
  EXPECT_GT(scene.deepest(0), -1e-3);
  EXPECT_GT(scene.world().last_step_stats().rows_contact, 0);  // it is on the ground
  EXPECT_LE(scene.max_energy_ratio(0), 1.01);
}

}  // namespace
}  // namespace taut
