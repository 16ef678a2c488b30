// The box_on_sphere scene: a three-box rigid stack on a soft energy-limited sphere stays stacked
// and upright, with rigid-rigid rows solved inside the sphere's island.
#include "demos/scenes/box_on_sphere_scene.h"

#include <gtest/gtest.h>

namespace taut {
namespace {

TEST(BoxOnSphereSceneTest, StackRestsOnTheLimitedSphereUprightAndInContact) {
  BoxOnSphereScene scene;
  const double start0 = scene.box_height(0);
  for (int i = 0; i < 480; ++i) scene.Step(1.0 / 240.0);
  nlohmann::json figures;
  scene.WriteFigures(figures);
  std::printf("box_on_sphere after 2 s: %s\n", figures.dump().c_str());
  const StepStats& stats = scene.world().last_step_stats();
  EXPECT_EQ(stats.rigid_bodies_coupled, 3);
  EXPECT_GT(figures["max_rigid_contact_rows"].get<int>(), 0);
  EXPECT_LT(scene.max_tilt(), 5.0 * M_PI / 180.0);
  for (double gap : figures["box_gaps_m"]) EXPECT_NEAR(gap, 0.0, 5e-3);  // stacked, touching
  EXPECT_LT(scene.max_penetration(), 5e-3);
  EXPECT_LT(scene.max_energy_ratio(), 1.01);
  EXPECT_LT(scene.box_height(0), start0);  // the sphere gave way under the stack
  EXPECT_GT(scene.CalcFlattening(), 0.002);
  // The energy limit is what holds the stack up: without it the sphere flattens more.
  BoxOnSphereScene unlimited(500e3, 0.0);
  for (int i = 0; i < 480; ++i) unlimited.Step(1.0 / 240.0);
  std::printf("flattening: limited %.4f, unlimited %.4f\n", scene.CalcFlattening(),
              unlimited.CalcFlattening());
  EXPECT_GT(unlimited.CalcFlattening(), 1.2 * scene.CalcFlattening());
  for (int k = 0; k < 3; ++k) EXPECT_LT(scene.box(k).getLinearVelocity().length(), 0.2);
}

}  // namespace
}  // namespace taut
