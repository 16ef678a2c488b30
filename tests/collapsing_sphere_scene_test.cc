#include "demos/scenes/collapsing_sphere_scene.h"

#include <gtest/gtest.h>

#include <cstdio>

namespace taut {
namespace {

// Paper B Fig. 5 on a coarser 81-hex sphere (cell 0.4 m; the scene's default is 280 hexes) past
// its deepest compression (impact at ~0.32 s, deepest at ~0.6 s): the unlimited 50 kPa sphere
// collapses, its elements far past 50 J and nearly flattened; the limited one keeps every
// U_e <= 50 J within the SQP tolerance (C = 1 - U_e/U_max >= -1e-3) and flattens far less.
TEST(CollapsingSphereSceneTest, EnergyLimitStopsTheCollapse) {
  CollapsingSphereScene scene(CollapsingSphereScene::DefaultSpheres(), 0.4, 0.5);
  ASSERT_EQ(scene.num_spheres(), 2);
  for (int step = 0; step < 72; ++step) scene.Step(1.0 / 120.0);
  for (int s = 0; s < 2; ++s) {
    std::printf("%-18s flattening %.3f, U/Umax %.4f, volume ratio %.3f, penetration %.1e m\n",
                scene.world().deformable_body(s).name().c_str(), scene.max_flattening(s),
                scene.max_energy_ratio(s), scene.min_volume_ratio(s), scene.deepest_penetration(s));
    EXPECT_LT(scene.deepest_penetration(s), 1e-3);  // the SQP tolerance on contact gaps [m]
  }
  EXPECT_GT(scene.max_flattening(0), 0.3);    // the soft one collapsed
  EXPECT_GT(scene.max_energy_ratio(0), 3.0);  // far past 50 J
  EXPECT_LT(scene.max_flattening(1), 0.6 * scene.max_flattening(0));
  EXPECT_GT(scene.max_flattening(1), 0.05);  // it did deform
  EXPECT_LE(scene.max_energy_ratio(1), 1.002);
  EXPECT_GT(scene.min_volume_ratio(1), scene.min_volume_ratio(0));  // less volume lost
}

TEST(CollapsingSphereSceneTest, BadSizesThrow) {
  EXPECT_THROW(CollapsingSphereScene(CollapsingSphereScene::DefaultSpheres(), 0.0), InputError);
  EXPECT_THROW(CollapsingSphereScene(CollapsingSphereScene::DefaultSpheres(), 0.4, -1.0),
               InputError);
}

}  // namespace
}  // namespace taut
