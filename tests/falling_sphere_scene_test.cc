#include "demos/scenes/falling_sphere_scene.h"

#include <gtest/gtest.h>

#include <cstdio>

namespace taut {
namespace {

// Paper B Fig. 4 claims after 1.5 s (impact at ~0.64 s): the soft sphere flattens most, the
// energy-limited one much less (its limit holds), nothing sinks into the ground.
TEST(FallingSphereSceneTest, EnergyLimitStiffensTheImpactAndContactHolds) {
  FallingSphereScene scene(FallingSphereScene::DefaultSpheres());
  for (int step = 0; step < 360; ++step) scene.Step(1.0 / 240.0);
  for (int s = 0; s < 3; ++s) {
    std::printf("%-20s flattening %.3f, bounce %.3f m, penetration %.1e m, U/Umax %.4f\n",
                scene.world().deformable_body(s).name().c_str(), scene.max_flattening(s),
                scene.bounce_height(s), -scene.deepest_penetration(s), scene.max_energy_ratio(s));
    EXPECT_GT(scene.deepest_penetration(s), -1e-3);
    EXPECT_GT(scene.max_flattening(s), 0.01);  // it landed and deformed
  }
  EXPECT_GT(scene.max_flattening(0), 1.5 * scene.max_flattening(1));  // soft vs stiff
  EXPECT_LT(scene.max_flattening(2), 0.8 * scene.max_flattening(0));  // limited vs soft
  EXPECT_LE(scene.max_energy_ratio(2), 1.01);
}

// The primal path on the three spheres' ground contacts (hexes with embedded surface points:
// several contact points share a cell's nodes, so their normal multipliers are not unique and an
// update may move load between them): every step of the first second, impact included, passes
// its certificate. Before the certificate fitted friction forces to the rims of the current
// Coulomb disks, 16 of these 240 steps failed it (steps 155-224; 35 of the scene's 480).
TEST(FallingSphereSceneTest, PrimalPathCertifiesEveryContactStep) {
  FallingSphereScene scene(FallingSphereScene::DefaultSpheres());
  scene.mutable_solver_settings().solver = IslandSolverKind::kPrimal;
  int unconverged = 0, primal_islands = 0;
  for (int step = 0; step < 240; ++step) {
    scene.Step(1.0 / 240.0);
    if (!scene.last_step_stats().converged) ++unconverged;
    primal_islands += scene.last_step_stats().islands_primal;
  }
  EXPECT_EQ(unconverged, 0);
  EXPECT_EQ(primal_islands, 3 * 240);
  for (int s = 0; s < 3; ++s) EXPECT_GT(scene.deepest_penetration(s), -1e-3);
}

}  // namespace
}  // namespace taut
