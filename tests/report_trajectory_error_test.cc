#include <gtest/gtest.h>

#include <cmath>

#include "demos/tools/report/trajectory_error.h"

namespace taut {
namespace {

// The unit cube's 8 corners have a bounding-box diagonal sqrt(3); shifting them changes nothing.
TEST(ReportTrajectoryErrorTest, BoundingBoxDiagonalOfCube) {
  VecX corners(24);
  for (int i = 0; i < 8; ++i)
    corners.segment<3>(3 * i) = Vec3(i & 1, (i >> 1) & 1, (i >> 2) & 1) + Vec3(5.0, -2.0, 0.5);
  EXPECT_NEAR(CalcBoundingBoxDiagonal(corners), std::sqrt(3.0), 1e-14);
  // A box of 2 x 3 x 6 from two opposite corners.
  VecX box(6);
  box << 0.0, 0.0, 0.0, 2.0, 3.0, 6.0;
  EXPECT_NEAR(CalcBoundingBoxDiagonal(box), 7.0, 1e-14);
  EXPECT_THROW(CalcBoundingBoxDiagonal(VecX(4)), InputError);
  EXPECT_THROW(CalcBoundingBoxDiagonal(VecX(0)), InputError);
}

// Two bodies by hand: body 0 (L = 2) has nodes off by 0.2 and 0, body 1 (L = 1) one node off by
// 0.1: e = sqrt((0.2^2 / 4 + 0 + 0.1^2 / 1) / 3).
TEST(ReportTrajectoryErrorTest, NormalizedRmsDistanceByHand) {
  TrajectorySample x_ref = {VecX::Zero(6), VecX::Zero(3)};
  TrajectorySample x = x_ref;
  x[0][0] = 0.2;
  x[1][1] = -0.1;
  const double expected = std::sqrt((0.04 / 4.0 + 0.01) / 3.0);
  EXPECT_NEAR(CalcNormalizedRmsDistance(x, x_ref, {2.0, 1.0}), expected, 1e-15);
  EXPECT_EQ(CalcNormalizedRmsDistance(x_ref, x_ref, {2.0, 1.0}), 0.0);
}

// Translating every node of a body by d gives e = |d| / L whatever the node count.
TEST(ReportTrajectoryErrorTest, TranslationGivesDistanceOverLength) {
  const Vec3 d(0.03, -0.04, 0.0);  // |d| = 0.05
  VecX x_ref = VecX::LinSpaced(30, -1.0, 2.0);
  VecX x = x_ref;
  for (int i = 0; i < 10; ++i) x.segment<3>(3 * i) += d;
  EXPECT_NEAR(CalcNormalizedRmsDistance({x}, {x_ref}, {0.5}), 0.05 / 0.5, 1e-14);
}

// Mismatched bodies, node counts or a zero length throw InputError.
TEST(ReportTrajectoryErrorTest, MismatchThrows) {
  const TrajectorySample one = {VecX::Zero(6)};
  EXPECT_THROW(CalcNormalizedRmsDistance(one, {VecX::Zero(6), VecX::Zero(3)}, {1.0}), InputError);
  EXPECT_THROW(CalcNormalizedRmsDistance(one, {VecX::Zero(3)}, {1.0}), InputError);
  EXPECT_THROW(CalcNormalizedRmsDistance(one, one, {0.0}), InputError);
  EXPECT_THROW(CalcNormalizedRmsDistance(one, one, {}), InputError);
}

// Samples match in layout only with the same body count and the same free nodes per body.
TEST(ReportTrajectoryErrorTest, SameLayout) {
  const TrajectorySample a = {VecX::Zero(6), VecX::Zero(3)};
  EXPECT_TRUE(HaveSameLayout(a, {VecX::Ones(6), VecX::Ones(3)}));
  EXPECT_FALSE(HaveSameLayout(a, {VecX::Zero(6)}));
  EXPECT_FALSE(HaveSameLayout(a, {VecX::Zero(6), VecX::Zero(6)}));
  EXPECT_FALSE(HaveSameLayout(a, {}));
}

// RMS and median of small lists; none gives NaN.
TEST(ReportTrajectoryErrorTest, RmsAndMedian) {
  EXPECT_NEAR(CalcRms({3.0, 4.0}), std::sqrt(12.5), 1e-15);
  EXPECT_EQ(CalcMedian({5.0, 1.0, 3.0}), 3.0);
  EXPECT_EQ(CalcMedian({4.0, 1.0, 10.0, 2.0}), 3.0);
  EXPECT_EQ(CalcMedian({7.0}), 7.0);
  EXPECT_TRUE(std::isnan(CalcRms({})));
  EXPECT_TRUE(std::isnan(CalcMedian({})));
}

}  // namespace
}  // namespace taut
