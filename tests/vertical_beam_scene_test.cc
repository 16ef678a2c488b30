#include "demos/scenes/vertical_beam_scene.h"

#include <gtest/gtest.h>

namespace taut {
namespace {

// Paper A Fig. 4 claims on a coarse column (1 x 1 x 4 cubes), 100 steps of 1/240 s.
TEST(VerticalBeamSceneTest, HyperbolicAndEllipsoidHoldTheTransverseLimitOrthogonalFreezes) {
  VerticalBeamScene scene({StrainProjection::kHyperbolic, StrainProjection::kEllipsoid,
                           StrainProjection::kOrthogonal},
                          1, 4);
  for (int step = 0; step < 100; ++step) scene.Step(1.0 / 240.0);
  for (int c = 0; c < 2; ++c) {
    // The column collapses (no freezing) ...
    EXPECT_LT(scene.CalcTopHeight(c), 0.9) << "column " << c;
    // ... and the strain along the limited axis stays within MATH.md §3's bound for the
    // hyperbolic rule, 1 + d / max(|cos phi|, |sin phi|) <= 1 + sqrt(2) d, plus the tolerance.
    EXPECT_GT(scene.first_violation_step(c), 0);
    EXPECT_LT(scene.max_limited_axis_strain(c), 0.05 * std::sqrt(2.0) + 0.005) << "column " << c;
    EXPECT_TRUE(scene.world().deformable_body(c).x().allFinite());
  }
  // One limited axis: ellipsoid equals hyperbolic (MATH.md §3).
  EXPECT_NEAR(scene.max_limited_axis_strain(0), scene.max_limited_axis_strain(1), 1e-6);
  // Orthogonal projection: violated in the first step, the column stays near its rest height.
  EXPECT_EQ(scene.first_violation_step(2), 1);
  EXPECT_GT(scene.CalcTopHeight(2), 0.95);
  EXPECT_LT(scene.CalcTopHeight(0), scene.CalcTopHeight(2) - 0.1);
}

}  // namespace
}  // namespace taut
