#include "demos/scenes/tet_beam_scene.h"

#include <gtest/gtest.h>

namespace taut {
namespace {

// Paper A Fig. 2 on coarse beams (5 x 1 x 1 cubes): the soft beam sags more than the stiff one,
// and the anisotropic beam (free along its axis) stretches along it clearly more than the
// isotropic one, whose 4 % limit holds.
TEST(TetBeamSceneTest, SoftSagsMoreAndAnisotropicStretchesMoreThanIsotropic) {
  TetBeamScene scene(TetBeamScene::DefaultBeams(), 5, 1);
  for (int step = 0; step < 120; ++step) scene.Step(1.0 / 240.0);
  const double stiff = scene.CalcTipDisplacement(0).norm();
  const double soft = scene.CalcTipDisplacement(1).norm();
  const double anisotropic_length = scene.CalcLength(2);
  const double isotropic_length = scene.CalcLength(3);
  std::printf("tip: stiff %.3f m, soft %.3f m; length: anisotropic %.3f m, isotropic %.3f m\n",
              stiff, soft, anisotropic_length, isotropic_length);
  EXPECT_GT(soft, 1.2 * stiff);
  EXPECT_GT(anisotropic_length, isotropic_length + 0.05);
  // The isotropic beam's axis can stretch at most 4 % (plus the solver tolerance).
  EXPECT_LT(isotropic_length, 1.04 * 1.0 + 0.01);
  for (int b = 0; b < 4; ++b) EXPECT_TRUE(scene.world().deformable_body(b).x().allFinite());
}

}  // namespace
}  // namespace taut
