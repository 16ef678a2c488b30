#include "plugin/signed_svd.h"

#include <gtest/gtest.h>

#include "tests/test_utils.h"

namespace taut {
namespace {

// U, V rotations, G reconstructed, |s| sorted, sign(s_3) = sign(det G).
void ExpectSignedSvdInvariants(const Mat3& G) {
  const SignedSvd svd = CalcSignedSvd(G);
  EXPECT_NEAR(svd.U.determinant(), 1.0, 1e-12);
  EXPECT_NEAR(svd.V.determinant(), 1.0, 1e-12);
  EXPECT_LT((svd.U * svd.s.asDiagonal() * svd.V.transpose() - G).norm(), 1e-12 * (1 + G.norm()));
  EXPECT_GE(std::abs(svd.s[0]), std::abs(svd.s[1]));
  EXPECT_GE(std::abs(svd.s[1]), std::abs(svd.s[2]));
  EXPECT_EQ(svd.s[2] < 0.0, G.determinant() < 0.0);
}

TEST(SignedSvdTest, RandomAndInvertedMatrices) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  for (int trial = 0; trial < 2000; ++trial) {
    Mat3 G;
    for (int k = 0; k < 9; ++k) G.data()[k] = u(rng);
    ExpectSignedSvdInvariants(G);
  }
}

TEST(SignedSvdTest, ReflectionIsInvertedNotIdentity) {
  // With unsigned values a reflection has s = (1,1,1) and passes every strain limit
  // (docs/math.md §0.2).
  const Mat3 G = Vec3(1, 1, -1).asDiagonal();
  const SignedSvd svd = CalcSignedSvd(G);
  EXPECT_NEAR(svd.s[2], -1.0, 1e-14);
  const Mat3 R = CalcPolarRotation(G);
  EXPECT_NEAR(R.determinant(), 1.0, 1e-14);
}

TEST(SignedSvdTest, PolarRotationOfRotatedStretch) {
  std::mt19937 rng(2);
  const Mat3 Q = testing::RandomRotation(rng);
  const Mat3 G = Q * Vec3(1.3, 0.9, 0.7).asDiagonal();
  EXPECT_LT((CalcPolarRotation(G) - Q).norm(), 1e-12);
}

}  // namespace
}  // namespace taut
