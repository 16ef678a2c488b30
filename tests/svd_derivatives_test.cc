// Finite-difference checks of the signed-SVD derivatives (docs/math.md §1-§2 and §2 R1).
#include "constraints/svd_derivatives.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "tests/test_utils.h"

namespace taut {
namespace {

using testing::RandomRotation;

// A random positively oriented rest tet (perturbed regular tet) and its rest rows r_1..r_4.
TetRestRows RandomRestRows(std::mt19937* rng, std::array<Vec3, 4>* X_out) {
  std::uniform_real_distribution<double> u(-0.15, 0.15);
  std::array<Vec3, 4> X = {Vec3(1, 1, 1), Vec3(1, -1, -1), Vec3(-1, 1, -1), Vec3(-1, -1, 1)};
  for (Vec3& p : X) p = 0.3 * (p + Vec3(u(*rng), u(*rng), u(*rng)));
  Mat3 X0;
  for (int c = 0; c < 3; ++c) X0.col(c) = X[c] - X[3];
  if (X0.determinant() < 0) std::swap(X[0], X[1]);
  for (int c = 0; c < 3; ++c) X0.col(c) = X[c] - X[3];
  const Mat3 inv = X0.inverse();
  TetRestRows r;
  for (int n = 0; n < 3; ++n) r[n] = inv.row(n).transpose();
  r[3] = -(r[0] + r[1] + r[2]);
  if (X_out) *X_out = X;
  return r;
}

// Node positions x_n = G X_n + t, so that G is the tet's deformation gradient.
TetPositions PositionsFromG(const Mat3& G, const std::array<Vec3, 4>& X, const Vec3& t) {
  TetPositions x;
  for (int n = 0; n < 4; ++n) x[n] = G * X[n] + t;
  return x;
}

// Signed SVD of G(x + h e_c), with each (u_i, v_i) pair sign-aligned to the reference SVD.
SignedSvd PerturbedSvd(const TetPositions& x, const TetRestRows& r, int c, double h,
                       const SignedSvd& ref) {
  TetPositions xp = x;
  xp[c / 3][c % 3] += h;
  SignedSvd svd = CalcSignedSvd(CalcTetDeformationGradient(r, xp));
  for (int i = 0; i < 3; ++i) {
    if (svd.V.col(i).dot(ref.V.col(i)) < 0) {
      svd.V.col(i) *= -1.0;
      svd.U.col(i) *= -1.0;
    }
  }
  return svd;
}

// Central FD of s_i and of column v_i with step h.
void CalcFdSvd(const TetPositions& x, const TetRestRows& r, int i, double h, Vec12* ds,
               Mat3x12* dv) {
  const SignedSvd ref = CalcSignedSvd(CalcTetDeformationGradient(r, x));
  for (int c = 0; c < 12; ++c) {
    const SignedSvd p = PerturbedSvd(x, r, c, h, ref);
    const SignedSvd m = PerturbedSvd(x, r, c, -h, ref);
    (*ds)[c] = (p.s[i] - m.s[i]) / (2 * h);
    dv->col(c) = (p.V.col(i) - m.V.col(i)) / (2 * h);
  }
}

// Smallest |s_a - s_b| and |s_a + s_b| over pairs: the distance to a singularity of dV.
double MinGap(const Vec3& s) {
  double gap = 1e300;
  for (int a = 0; a < 3; ++a)
    for (int b = a + 1; b < 3; ++b)
      gap = std::min({gap, std::abs(s[a] - s[b]), std::abs(s[a] + s[b])});
  return gap;
}

// Random G = U diag(s) V^T with s_i ~ U[0.5, 1.5]; inverted (s_3 < 0) when `inverted`.
Mat3 RandomG(std::mt19937* rng, bool inverted) {
  std::uniform_real_distribution<double> u(0.5, 1.5);
  Vec3 s(u(*rng), u(*rng), u(*rng));
  if (inverted) s[2] = -s[2];
  return RandomRotation(*rng) * s.asDiagonal() * RandomRotation(*rng).transpose();
}

double Percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  return v[static_cast<size_t>(p * (v.size() - 1))];
}

TEST(SvdDerivativesTest, SingularValueGradientMatchesFdOnRandomAndInvertedStates) {
  std::mt19937 rng(1);
  std::vector<double> errors;
  for (int trial = 0; trial < 2000; ++trial) {
    const bool inverted = trial % 2 == 1;
    std::array<Vec3, 4> X;
    const TetRestRows r = RandomRestRows(&rng, &X);
    const Mat3 G = RandomG(&rng, inverted);
    const TetPositions x = PositionsFromG(G, X, Vec3(0.3, -0.2, 0.1));
    const SignedSvd svd = CalcSignedSvd(CalcTetDeformationGradient(r, x));
    ASSERT_EQ(svd.s[2] < 0, inverted);
    if (MinGap(svd.s) < 0.05) continue;
    for (int i = 0; i < 3; ++i) {
      Vec12 ds_fd;
      Mat3x12 dv_fd;
      CalcFdSvd(x, r, i, 1e-6, &ds_fd, &dv_fd);
      const Vec12 ds = CalcSingularValueGradient(svd, r, i);
      ASSERT_GT(ds.norm(), 1e-3);
      errors.push_back((ds - ds_fd).norm() / ds_fd.norm());
    }
  }
  std::printf("[ ds/dx ] %zu gradients: median %.2e, max %.2e\n", errors.size(),
              Percentile(errors, 0.5), Percentile(errors, 1.0));
  EXPECT_LT(Percentile(errors, 1.0), 1e-7);
}

TEST(SvdDerivativesTest, SingularVectorGradientMatchesFdOnRandomAndInvertedStates) {
  std::mt19937 rng(2);
  std::vector<double> errors;
  for (int trial = 0; trial < 2000; ++trial) {
    std::array<Vec3, 4> X;
    const TetRestRows r = RandomRestRows(&rng, &X);
    const TetPositions x = PositionsFromG(RandomG(&rng, trial % 2 == 1), X, Vec3::Zero());
    const SignedSvd svd = CalcSignedSvd(CalcTetDeformationGradient(r, x));
    if (MinGap(svd.s) < 0.05) continue;
    for (int i = 0; i < 3; ++i) {
      Vec12 ds_fd;
      Mat3x12 dv_fd;
      CalcFdSvd(x, r, i, 1e-6, &ds_fd, &dv_fd);
      const Mat3x12 dv = CalcSingularVectorGradient(svd, r, i, 0.0);
      ASSERT_GT(dv.norm(), 1e-3);
      errors.push_back((dv - dv_fd).norm() / dv_fd.norm());
    }
  }
  std::printf("[ dV/dx ] %zu gradients (gaps >= 0.05): median %.2e, max %.2e\n", errors.size(),
              Percentile(errors, 0.5), Percentile(errors, 1.0));
  EXPECT_LT(Percentile(errors, 1.0), 1e-6);
}

// docs/math.md §2.2: the closed form stays exact as the gap closes when h << gap (h = 1e-3 gap).
TEST(SvdDerivativesTest, SingularVectorGradientExactNearRepeatedValuesWithSmallStep) {
  std::mt19937 rng(3);
  for (const bool inverted_pair : {false, true}) {
    for (const double delta : {1e-1, 1e-2, 1e-3, 1e-5, 1e-7}) {
      std::array<Vec3, 4> X;
      const TetRestRows r = RandomRestRows(&rng, &X);
      const Vec3 s = inverted_pair ? Vec3(1.5, 0.5, -0.5 + delta) : Vec3(1.2, 1.2 - delta, 0.8);
      const Mat3 G = RandomRotation(rng) * s.asDiagonal() * RandomRotation(rng).transpose();
      const TetPositions x = PositionsFromG(G, X, Vec3::Zero());
      const SignedSvd svd = CalcSignedSvd(CalcTetDeformationGradient(r, x));
      double max_err = 0.0, max_norm = 0.0;
      for (int i = 0; i < 3; ++i) {
        Vec12 ds_fd;
        Mat3x12 dv_fd;
        CalcFdSvd(x, r, i, 1e-3 * delta, &ds_fd, &dv_fd);
        const Mat3x12 dv = CalcSingularVectorGradient(svd, r, i, 0.0);
        ASSERT_GT(dv.norm(), 1e-3);
        max_err = std::max(max_err, (dv - dv_fd).norm() / dv_fd.norm());
        max_norm = std::max(max_norm, dv.cwiseAbs().maxCoeff());
        // ds is O(1), so at h = 1e-10 the FD is round-off limited (~1e-16 / h).
        EXPECT_LT((CalcSingularValueGradient(svd, r, i) - ds_fd).norm(), 1e-4 * ds_fd.norm());
      }
      std::printf("[ dV/dx near-repeated %s ] delta %.0e: max|dV| %.2e, rel err %.2e\n",
                  inverted_pair ? "s2=-s3" : "s1=s2", delta, max_norm, max_err);
      EXPECT_LT(max_err, 1e-5) << "delta " << delta;
    }
  }
}

// R1: the clamp changes a column's gradient exactly when one of its gaps is below epsilon.
TEST(SvdDerivativesTest, GapClampActsOnlyBelowEpsilon) {
  std::mt19937 rng(4);
  std::array<Vec3, 4> X;
  const TetRestRows r = RandomRestRows(&rng, &X);
  const Mat3 Ru = RandomRotation(rng), Rv = RandomRotation(rng);
  // s_1^2 - s_2^2 = 2.4 delta - delta^2: above 1e-2 at delta = 1e-2, below at 1e-3 and 1e-5.
  for (const double delta : {1e-2, 1e-3, 1e-5}) {
    const Vec3 s(1.2, 1.2 - delta, 0.8);
    const TetPositions x = PositionsFromG(Ru * s.asDiagonal() * Rv.transpose(), X, Vec3::Zero());
    const SignedSvd svd = CalcSignedSvd(CalcTetDeformationGradient(r, x));
    const bool small_gap = delta < 1e-2;
    for (int i = 0; i < 3; ++i) {
      const bool expect_active = small_gap && i != 2;  // column 3 has gaps 0.8 and 0.64
      EXPECT_EQ(IsSvdGapClampActive(svd.s, i, 1e-2), expect_active);
      const Mat3x12 clamped = CalcSingularVectorGradient(svd, r, i, 1e-2);
      const Mat3x12 exact = CalcSingularVectorGradient(svd, r, i, 0.0);
      Vec12 ds_fd;
      Mat3x12 dv_fd;
      CalcFdSvd(x, r, i, 1e-3 * delta, &ds_fd, &dv_fd);
      EXPECT_LT((exact - dv_fd).norm(), 1e-5 * dv_fd.norm());
      if (expect_active) {
        // Clamped: bounded by about 1/epsilon, no longer the derivative.
        EXPECT_GT((clamped - dv_fd).norm(), 0.1 * dv_fd.norm());
        EXPECT_LT(clamped.cwiseAbs().maxCoeff(), 1e3);
      } else {
        EXPECT_EQ((clamped - exact).norm(), 0.0);
      }
    }
  }
  // sgn(0) = +1 on the ordered pair, negated for the reverse order (antisymmetric Omega).
  const Vec3 equal(1.1, 1.1, 0.9);
  EXPECT_EQ(CalcClampedGapDenominator(equal, 0, 1, 1e-2), 1e-2);
  EXPECT_EQ(CalcClampedGapDenominator(equal, 1, 0, 1e-2), -1e-2);
  EXPECT_NEAR(CalcClampedGapDenominator(equal, 0, 2, 1e-2), 1.21 - 0.81, 1e-15);
  EXPECT_NEAR(CalcClampedGapDenominator(equal, 2, 0, 1e-2), 0.81 - 1.21, 1e-15);
}

// The per-perturbation form: FD of U, s, V along dG, and the identity dG = dU S V^T + U dS V^T +
// U S dV^T.
TEST(SvdDerivativesTest, DifferentialMatchesFdAndReconstructsDG) {
  std::mt19937 rng(5);
  std::normal_distribution<double> n(0.0, 1.0);
  int checked = 0;
  for (int trial = 0; trial < 500; ++trial) {
    const Mat3 G = RandomG(&rng, trial % 3 == 0);
    Mat3 dG;
    for (int k = 0; k < 9; ++k) dG(k) = n(rng);
    const SignedSvd svd = CalcSignedSvd(G);
    if (MinGap(svd.s) < 0.05) continue;
    ++checked;
    const SvdDifferential d = CalcSvdDifferential(svd, dG, 0.0);
    ASSERT_GT(d.dV.norm(), 1e-3);
    ASSERT_GT(d.dU.norm(), 1e-3);
    const Mat3 S = svd.s.asDiagonal();
    const Mat3 recon = d.dU * S * svd.V.transpose() +
                       svd.U * d.ds.asDiagonal() * svd.V.transpose() + svd.U * S * d.dV.transpose();
    EXPECT_LT((recon - dG).norm(), 1e-12 * dG.norm());
    const double h = 1e-6;
    SignedSvd p = CalcSignedSvd(G + h * dG), m = CalcSignedSvd(G - h * dG);
    for (SignedSvd* q : {&p, &m}) {
      for (int i = 0; i < 3; ++i) {
        if (q->V.col(i).dot(svd.V.col(i)) < 0) {
          q->V.col(i) *= -1.0;
          q->U.col(i) *= -1.0;
        }
      }
    }
    EXPECT_LT(((p.U - m.U) / (2 * h) - d.dU).norm(), 1e-6 * d.dU.norm());
    EXPECT_LT(((p.V - m.V) / (2 * h) - d.dV).norm(), 1e-6 * d.dV.norm());
    EXPECT_LT(((p.s - m.s) / (2 * h) - d.ds).norm(), 1e-6 * d.ds.norm());
  }
  EXPECT_GT(checked, 300);
}

// The closed form equals the generic form with dG = e_k r_n^T, also with the clamp active, and
// the node blocks sum to zero (translation invariance, sum_n r_n = 0).
TEST(SvdDerivativesTest, ClosedFormEqualsGenericFormAndIsTranslationInvariant) {
  std::mt19937 rng(6);
  for (int trial = 0; trial < 50; ++trial) {
    std::array<Vec3, 4> X;
    const TetRestRows r = RandomRestRows(&rng, &X);
    // Every third state has nearly repeated values, so the clamp is active.
    Mat3 G = RandomG(&rng, trial % 2 == 0);
    if (trial % 3 == 0) G = RandomRotation(rng) * Vec3(1.1, 1.1 - 1e-4, 0.7).asDiagonal();
    const SignedSvd svd = CalcSignedSvd(G);
    for (int i = 0; i < 3; ++i) {
      const Mat3x12 dv = CalcSingularVectorGradient(svd, r, i, 1e-2);
      Mat3x12 node_sum = Mat3x12::Zero();
      for (int c = 0; c < 12; ++c) {
        const Mat3 dG = Vec3::Unit(c % 3) * r[c / 3].transpose();
        const SvdDifferential d = CalcSvdDifferential(svd, dG, 1e-2);
        EXPECT_LT((d.dV.col(i) - dv.col(c)).norm(), 1e-12 * (1.0 + dv.norm()));
        EXPECT_NEAR(d.ds[i], CalcSingularValueGradient(svd, r, i)[c], 1e-14);
      }
      for (int n = 0; n < 4; ++n) node_sum.leftCols<3>() += dv.block<3, 3>(0, 3 * n);
      EXPECT_LT(node_sum.norm(), 1e-10 * (1.0 + dv.norm()));
    }
  }
}

}  // namespace
}  // namespace taut
