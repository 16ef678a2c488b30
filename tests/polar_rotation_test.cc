#include "plugin/polar_rotation.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include "plugin/signed_svd.h"
#include "tests/test_utils.h"

namespace taut {
namespace {

using testing::RandomRotation;

// Q1 diag(s) Q2 for random rotations Q1, Q2; its polar rotation is Q1 Q2 when every s_i > 0.
struct RotatedStretch {
  Mat3 G;
  Mat3 R;
};
RotatedStretch MakeRotatedStretch(std::mt19937& rng, const Vec3& s) {
  const Mat3 Q1 = RandomRotation(rng), Q2 = RandomRotation(rng);
  return {Q1 * s.asDiagonal() * Q2, Q1 * Q2};
}

// Deformation gradients R (I + a X), X uniform in [-1, 1]^9, as elements see them (a up to 0.6;
// some are inverted at the larger a) and at scales far from 1: Newton's rotation is the SVD's to
// a few 1e-15 wherever det G > 0, a rotation with R^T G symmetric positive definite.
TEST(PolarRotationTest, MatchesTheSignedSvdRotationOnElementGradients) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double worst = 0.0;
  for (double amplitude : {1e-3, 0.1, 0.3, 0.6}) {
    for (double scale : {1.0, 1e-6, 1e6}) {
      for (int trial = 0; trial < 300; ++trial) {
        Mat3 X;
        for (int k = 0; k < 9; ++k) X.data()[k] = u(rng);
        const Mat3 G = scale * RandomRotation(rng) * (Mat3::Identity() + amplitude * X);
        const Mat3 R = CalcPolarRotation(G);
        const Mat3 reference = CalcPolarRotationBySvd(G);
        if (G.determinant() <= 0.0) {
          EXPECT_EQ(R, reference);  // inverted: the SVD's rotation itself
          continue;
        }
        worst = std::max(worst, (R - reference).norm());
        EXPECT_LE((R - reference).norm(), 1e-14) << amplitude << " " << scale;
        EXPECT_LE((R.transpose() * R - Mat3::Identity()).norm(), 1e-14);
        const Mat3 S = R.transpose() * G / scale;
        EXPECT_LE((S - S.transpose()).norm(), 1e-13 * S.norm());
        EXPECT_GT(Eigen::SelfAdjointEigenSolver<Mat3>(0.5 * (S + S.transpose())).eigenvalues()[0],
                  0.0);
      }
    }
  }
  std::printf("largest |R - U V^T|: %.3g\n", worst);
}

// Stretches down to s_3 / s_1 = 1e-8 (one or two small values): the known rotation Q1 Q2 to the
// accuracy the problem allows, |dR| ~ eps s_1 / (s_2 + s_3) (the polar factor's condition number;
// Higham 1986), within 50 times that.
TEST(PolarRotationTest, IllConditionedStretchesKeepTheSvdsAccuracy) {
  std::mt19937 rng(12);
  for (double small : {0.5, 1e-2, 1e-4, 1e-6, 1e-8}) {
    for (const Vec3& s : {Vec3(1.0, 1.0, small), Vec3(1.0, 3.0 * small, small)}) {
      for (int trial = 0; trial < 100; ++trial) {
        const RotatedStretch case_ = MakeRotatedStretch(rng, s);
        const double error = (CalcPolarRotation(case_.G) - case_.R).norm();
        const double eps = std::numeric_limits<double>::epsilon();
        EXPECT_LE(error, 50.0 * eps * s[0] / (s[1] + s[2])) << s.transpose();
      }
    }
  }
}

// Exact rotations, times any positive scale, come back as themselves.
TEST(PolarRotationTest, ScaledRotationsAreExactToRoundOff) {
  std::mt19937 rng(13);
  for (int trial = 0; trial < 200; ++trial) {
    const Mat3 Q = RandomRotation(rng);
    for (double scale : {1.0, 2.5, 1e-3, 1e5})
      EXPECT_LE((CalcPolarRotation(scale * Q) - Q).norm(), 1e-14);
  }
  EXPECT_EQ(CalcPolarRotation(Mat3::Identity()), Mat3::Identity());
}

// Where det G <= 0 or G is not finite, the signed SVD answers: bit for bit its U V^T (a rotation
// also for inverted G; identity for G = 0; NaN for NaN input).
TEST(PolarRotationTest, InvertedSingularAndNonFiniteInputTakeTheSvdRotation) {
  std::mt19937 rng(14);
  for (int trial = 0; trial < 100; ++trial) {
    for (const Vec3& s :
         {Vec3(1.0, 0.9, -0.8), Vec3(1.2, 1.0, 0.0), Vec3(1.0, 1.0, -1.0), Vec3(2.0, 0.0, 0.0)}) {
      const Mat3 G = MakeRotatedStretch(rng, s).G;
      const Mat3 R = CalcPolarRotation(G);
      EXPECT_EQ(R, CalcPolarRotationBySvd(G)) << s.transpose();
      EXPECT_NEAR(R.determinant(), 1.0, 1e-13);
    }
  }
  EXPECT_EQ(CalcPolarRotation(Mat3::Zero()), Mat3::Identity());
  Mat3 nan_entry = Mat3::Identity();
  nan_entry(1, 2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(CalcPolarRotation(nan_entry).hasNaN());
  Mat3 infinite_entry = Mat3::Identity();
  infinite_entry(0, 0) = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(CalcPolarRotation(infinite_entry).allFinite());
}

}  // namespace
}  // namespace taut
