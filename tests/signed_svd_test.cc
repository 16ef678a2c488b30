#include "plugin/signed_svd.h"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "plugin/polar_rotation.h"
#include "tests/test_utils.h"

namespace taut {
namespace {

using testing::RandomRotation;

// Largest errors seen by ExpectSignedSvdInvariants, printed by the tests that sample many
// matrices.
struct SvdErrors {
  double reconstruction = 0.0;  // ||U diag(s) V^T - G|| / (1 + ||G||)
  double orthogonality = 0.0;   // max(||U^T U - I||, ||V^T V - I||)
  double determinant = 0.0;     // max(|det U - 1|, |det V - 1|)
  void Add(const SvdErrors& o) {
    reconstruction = std::max(reconstruction, o.reconstruction);
    orthogonality = std::max(orthogonality, o.orthogonality);
    determinant = std::max(determinant, o.determinant);
  }
  void Print(const char* what) const {
    std::printf("[ %s ] reconstruction %.2e, orthogonality %.2e, det %.2e\n", what, reconstruction,
                orthogonality, determinant);
  }
};

// U, V rotations (orthonormal within 1e-13, det within 1e-12), G reconstructed within
// 1e-13 (1 + ||G||), |s| sorted, sign(s_3) = sign(det G) (when det G is clearly nonzero).
SvdErrors ExpectSignedSvdInvariants(const Mat3& G) {
  const SignedSvd svd = CalcSignedSvd(G);
  SvdErrors e;
  e.reconstruction = (svd.U * svd.s.asDiagonal() * svd.V.transpose() - G).norm() / (1.0 + G.norm());
  e.orthogonality = std::max((svd.U.transpose() * svd.U - Mat3::Identity()).norm(),
                             (svd.V.transpose() * svd.V - Mat3::Identity()).norm());
  e.determinant =
      std::max(std::abs(svd.U.determinant() - 1.0), std::abs(svd.V.determinant() - 1.0));
  EXPECT_LE(e.reconstruction, 1e-13) << G;
  EXPECT_LE(e.orthogonality, 1e-13) << G;
  EXPECT_LE(e.determinant, 1e-12) << G;
  EXPECT_GE(std::abs(svd.s[0]), std::abs(svd.s[1])) << G;
  EXPECT_GE(std::abs(svd.s[1]), std::abs(svd.s[2])) << G;
  EXPECT_GE(svd.s[0], 0.0) << G;
  EXPECT_GE(svd.s[1], 0.0) << G;
  const double det = G.determinant();
  if (std::abs(det) > 1e-12 * std::pow(G.norm(), 3)) EXPECT_EQ(svd.s[2] < 0.0, det < 0.0) << G;
  return e;
}

// Eigen's singular values (non-negative, sorted descending).
Vec3 EigenSingularValues(const Mat3& G) { return Eigen::JacobiSVD<Mat3>(G).singularValues(); }

// Q1 diag(s) Q2^T with random rotations Q1, Q2.
Mat3 RotatedDiagonal(std::mt19937& rng, const Vec3& s) {
  return RandomRotation(rng) * s.asDiagonal() * RandomRotation(rng).transpose();
}

// True when every entry of M is 0, 1 or -1 and each row and column has one nonzero entry.
bool IsSignedPermutation(const Mat3& M) {
  for (int i = 0; i < 3; ++i) {
    int row_nonzero = 0, col_nonzero = 0;
    for (int j = 0; j < 3; ++j) {
      if (M(i, j) != 0.0 && std::abs(M(i, j)) != 1.0) return false;
      row_nonzero += M(i, j) != 0.0;
      col_nonzero += M(j, i) != 0.0;
    }
    if (row_nonzero != 1 || col_nonzero != 1) return false;
  }
  return true;
}

TEST(SignedSvdTest, RandomAndInvertedMatrices) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  SvdErrors worst;
  for (int trial = 0; trial < 2000; ++trial) {
    Mat3 G;
    for (int k = 0; k < 9; ++k) G.data()[k] = u(rng);
    worst.Add(ExpectSignedSvdInvariants(G));
  }
  worst.Print("random uniform entries");
}

// Many random matrices of the kinds the simulation sees (near-identity deformation gradients,
// some inverted) and general ones; |s| agrees with Eigen's JacobiSVD within 1e-12 s_max.
TEST(SignedSvdTest, SingularValuesMatchEigenJacobiSvd) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  SvdErrors worst;
  double worst_values = 0.0;
  for (int trial = 0; trial < 20000; ++trial) {
    Mat3 G;
    for (int k = 0; k < 9; ++k) G.data()[k] = u(rng);
    if (trial % 2 == 0) G = Mat3::Identity() + 0.1 * G;
    if (trial % 5 == 0) G.col(trial % 3) *= -1.0;  // inverted
    worst.Add(ExpectSignedSvdInvariants(G));
    const Vec3 ours = CalcSignedSvd(G).s.cwiseAbs();
    const Vec3 eigen = EigenSingularValues(G);
    const double err = (ours - eigen).lpNorm<Eigen::Infinity>() / eigen[0];
    worst_values = std::max(worst_values, err);
    EXPECT_LE(err, 1e-12) << G;
  }
  worst.Print("near-identity and general");
  std::printf("[ |s| vs Eigen JacobiSVD ] max error / s_max %.2e\n", worst_values);
}

// A diagonal input is returned exactly: sorted positive values give U = V = I; otherwise U, V are
// signed permutations and s the sorted values (signs on s_3 only).
TEST(SignedSvdTest, DiagonalInputIsExact) {
  const SignedSvd sorted = CalcSignedSvd(Vec3(3, 2, 1).asDiagonal());
  EXPECT_EQ(sorted.s, Vec3(3, 2, 1));
  EXPECT_EQ(sorted.U, Mat3::Identity());
  EXPECT_EQ(sorted.V, Mat3::Identity());

  const SignedSvd inverted = CalcSignedSvd(Vec3(3, 2, -1).asDiagonal());
  EXPECT_EQ(inverted.s, Vec3(3, 2, -1));
  EXPECT_EQ(inverted.U, Mat3::Identity());
  EXPECT_EQ(inverted.V, Mat3::Identity());

  for (const Vec3& d : {Vec3(1, 2, 3), Vec3(-1, 3, 2), Vec3(2, -3, -1), Vec3(0, 5, 1)}) {
    const Mat3 G = d.asDiagonal();
    const SignedSvd svd = CalcSignedSvd(G);
    Vec3 sorted_abs = d.cwiseAbs();
    std::sort(sorted_abs.data(), sorted_abs.data() + 3, [](double a, double b) { return a > b; });
    EXPECT_EQ(svd.s.cwiseAbs(), sorted_abs) << d.transpose();
    EXPECT_EQ(svd.s[2] < 0.0, G.determinant() < 0.0) << d.transpose();
    EXPECT_TRUE(IsSignedPermutation(svd.U)) << svd.U;
    EXPECT_TRUE(IsSignedPermutation(svd.V)) << svd.V;
    EXPECT_EQ(svd.U * svd.s.asDiagonal() * svd.V.transpose(), G) << d.transpose();
    EXPECT_EQ(svd.U.determinant(), 1.0);
    EXPECT_EQ(svd.V.determinant(), 1.0);
  }
}

// Values 1e-9 apart: each is resolved to round-off and the factors stay accurate.
TEST(SignedSvdTest, NearlyRepeatedValues) {
  std::mt19937 rng(4);
  for (int trial = 0; trial < 200; ++trial) {
    for (const Vec3& s : {Vec3(1 + 1e-9, 1, 0.5), Vec3(1.5, 1 + 1e-9, 1), Vec3(1, 1, 1 - 1e-9),
                          Vec3(1 + 1e-9, 1, -0.5)}) {
      const Mat3 G = RotatedDiagonal(rng, s);
      ExpectSignedSvdInvariants(G);
      const SignedSvd svd = CalcSignedSvd(G);
      EXPECT_LE((svd.s - s).lpNorm<Eigen::Infinity>(), 1e-14) << s.transpose();
    }
  }
}

// Rotations, scaled rotations, the identity and doubly repeated values: any basis of the
// repeated subspace is fine, but the values and the polar rotation are exact to round-off.
TEST(SignedSvdTest, ExactlyRepeatedValues) {
  const SignedSvd identity = CalcSignedSvd(Mat3::Identity());
  EXPECT_EQ(identity.s, Vec3(1, 1, 1));
  EXPECT_EQ(identity.U, Mat3::Identity());
  EXPECT_EQ(identity.V, Mat3::Identity());
  std::mt19937 rng(5);
  for (int trial = 0; trial < 200; ++trial) {
    const Mat3 Q = RandomRotation(rng);
    for (double scale : {1.0, 2.5, 1e-3}) {
      ExpectSignedSvdInvariants(scale * Q);
      const SignedSvd svd = CalcSignedSvd(scale * Q);
      EXPECT_LE((svd.s - Vec3::Constant(scale)).norm(), 1e-14 * scale);
      EXPECT_LE((CalcPolarRotation(scale * Q) - Q).norm(), 1e-14);
    }
    for (const Vec3& s : {Vec3(2, 2, 1), Vec3(2, 1, 1), Vec3(2, 1, -1)}) {
      const Mat3 G = RotatedDiagonal(rng, s);
      ExpectSignedSvdInvariants(G);
      EXPECT_LE((CalcSignedSvd(G).s - s).norm(), 1e-14) << s.transpose();
    }
  }
}

// Rank 1 and rank 2, including two small values below sqrt(eps) s_1 (where G^T G alone cannot
// separate v_2 from v_3) and matrices with exactly zero columns or rows.
TEST(SignedSvdTest, RankDeficientMatrices) {
  std::mt19937 rng(6);
  std::normal_distribution<double> n(0.0, 1.0);
  SvdErrors worst;
  for (int trial = 0; trial < 500; ++trial) {
    const Vec3 a(n(rng), n(rng), n(rng)), b(n(rng), n(rng), n(rng));
    const Mat3 rank1 = a * b.transpose();
    worst.Add(ExpectSignedSvdInvariants(rank1));
    const SignedSvd svd1 = CalcSignedSvd(rank1);
    EXPECT_NEAR(svd1.s[0], a.norm() * b.norm(), 1e-14 * svd1.s[0]);
    EXPECT_LE(svd1.s.tail<2>().cwiseAbs().maxCoeff(), 1e-14 * svd1.s[0]);
    for (const Vec3& s : {Vec3(2, 0.5, 0), Vec3(1, 1, 0), Vec3(1, 1e-9, 1e-12), Vec3(1, 1e-9, 0),
                          Vec3(1, 1e-12, -1e-14)}) {
      const Mat3 G = RotatedDiagonal(rng, s);
      worst.Add(ExpectSignedSvdInvariants(G));
      const Vec3 ours = CalcSignedSvd(G).s;
      EXPECT_LE((ours.cwiseAbs() - EigenSingularValues(G)).lpNorm<Eigen::Infinity>(), 1e-14)
          << s.transpose();
      EXPECT_LE((ours.cwiseAbs() - s.cwiseAbs()).lpNorm<Eigen::Infinity>(), 1e-14) << s.transpose();
    }
  }
  worst.Print("rank deficient");
  Mat3 zero_columns = Mat3::Zero();
  zero_columns.col(1) = Vec3(1, 2, -2);
  ExpectSignedSvdInvariants(zero_columns);
  EXPECT_EQ(CalcSignedSvd(zero_columns).s, Vec3(3, 0, 0));
  ExpectSignedSvdInvariants(zero_columns.transpose());
  EXPECT_EQ(CalcSignedSvd(zero_columns.transpose()).s, Vec3(3, 0, 0));
  Mat3 two_columns = Mat3::Zero();
  two_columns.col(0) = Vec3(0, 3, 4);
  two_columns.col(2) = Vec3(0, -4, 3);
  ExpectSignedSvdInvariants(two_columns);
  EXPECT_LE((CalcSignedSvd(two_columns).s - Vec3(5, 5, 0)).norm(), 1e-15);
}

TEST(SignedSvdTest, ZeroMatrix) {
  const SignedSvd svd = CalcSignedSvd(Mat3::Zero());
  EXPECT_EQ(svd.s, Vec3::Zero());
  EXPECT_EQ(svd.U, Mat3::Identity());
  EXPECT_EQ(svd.V, Mat3::Identity());
  EXPECT_EQ(CalcPolarRotation(Mat3::Zero()), Mat3::Identity());
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

// -I, Householder reflections and rotated reflections: s = (1, 1, -1), R = U V^T a rotation with
// R^T G = V diag(s) V^T symmetric.
TEST(SignedSvdTest, RandomReflectionsAreInverted) {
  EXPECT_EQ(CalcSignedSvd(-Mat3::Identity()).s, Vec3(1, 1, -1));
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    const Vec3 normal = Vec3(n(rng), n(rng), n(rng)).normalized();
    const Mat3 householder = Mat3::Identity() - 2.0 * normal * normal.transpose();
    for (const Mat3& G : {householder, Mat3(RandomRotation(rng) * householder)}) {
      ExpectSignedSvdInvariants(G);
      const SignedSvd svd = CalcSignedSvd(G);
      EXPECT_LE((svd.s - Vec3(1, 1, -1)).norm(), 1e-14);
      const Mat3 R = CalcPolarRotation(G);
      EXPECT_NEAR(R.determinant(), 1.0, 1e-13);
      const Mat3 stretch = R.transpose() * G;
      EXPECT_LE((stretch - stretch.transpose()).norm(), 1e-13);
    }
  }
}

// Flattened tets (smallest value 1e-6 or 1e-10, either sign): s_3 keeps its sign and, for 1e-6,
// its relative accuracy (1e-8); both agree with Eigen's JacobiSVD.
TEST(SignedSvdTest, SliversKeepTheirSmallestValue) {
  std::mt19937 rng(8);
  double worst_relative = 0.0;
  for (int trial = 0; trial < 1000; ++trial) {
    for (double smallest : {1e-6, -1e-6, 1e-10, -1e-10}) {
      const Vec3 s(1.0, 1.0, smallest);
      const Mat3 G = RotatedDiagonal(rng, s);
      ExpectSignedSvdInvariants(G);
      const Vec3 ours = CalcSignedSvd(G).s;
      const Vec3 eigen = EigenSingularValues(G);
      EXPECT_EQ(ours[2] < 0.0, smallest < 0.0);
      EXPECT_LE((ours.cwiseAbs() - eigen).lpNorm<Eigen::Infinity>(), 1e-12 * eigen[0]);
      if (std::abs(smallest) == 1e-6) {
        const double relative = std::abs(ours[2] / smallest - 1.0);
        worst_relative = std::max(worst_relative, relative);
        EXPECT_LE(relative, 1e-8);
        EXPECT_LE(std::abs(std::abs(ours[2]) / eigen[2] - 1.0), 1e-8);
      } else {
        EXPECT_LE(std::abs(ours[2] - smallest), 1e-15);
      }
    }
  }
  std::printf("[ sliver s_3 = 1e-6 ] max relative error of s_3 %.2e\n", worst_relative);
}

// The method is scale-invariant: s(c G) = c s(G) for c = 1e-150 and 1e150 (no underflow or
// overflow in G^T G), with the same U and V and a relative reconstruction error of 1e-13.
TEST(SignedSvdTest, TinyAndHugeScales) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    Mat3 G;
    for (int k = 0; k < 9; ++k) G.data()[k] = u(rng);
    if (trial % 4 == 0) G = RotatedDiagonal(rng, Vec3(1, 1, -1e-6));
    const SignedSvd reference = CalcSignedSvd(G);
    for (double scale : {1e-150, 1e150}) {
      const Mat3 scaled = scale * G;
      const SignedSvd svd = CalcSignedSvd(scaled);
      EXPECT_LE((svd.s / scale - reference.s).norm(), 1e-13 * reference.s[0]) << scale;
      EXPECT_LE((svd.U * svd.s.asDiagonal() * svd.V.transpose() - scaled).norm(),
                1e-13 * scaled.norm())
          << scale;
      EXPECT_LE((svd.U.transpose() * svd.U - Mat3::Identity()).norm(), 1e-13);
      EXPECT_LE((svd.V.transpose() * svd.V - Mat3::Identity()).norm(), 1e-13);
      EXPECT_LE((svd.U * svd.V.transpose() - reference.U * reference.V.transpose()).norm(), 1e-10)
          << scale;
    }
    // Scaling by a power of two changes no bit.
    const SignedSvd power = CalcSignedSvd(std::ldexp(1.0, -600) * G);
    EXPECT_EQ(power.s, std::ldexp(1.0, -600) * reference.s);
    EXPECT_EQ(power.U, reference.U);
    EXPECT_EQ(power.V, reference.V);
  }
}

TEST(SignedSvdTest, PolarRotationOfRotatedStretch) {
  std::mt19937 rng(2);
  const Mat3 Q = testing::RandomRotation(rng);
  const Mat3 G = Q * Vec3(1.3, 0.9, 0.7).asDiagonal();
  EXPECT_LT((CalcPolarRotation(G) - Q).norm(), 1e-12);
}

}  // namespace
}  // namespace taut
