// Second derivatives of signed singular values and the strain-row curvature built on them:
// FD checks (gap clamp off, well-separated values) and the PSD / boundedness of the clamped
// metric (constraints/singular_value_hessian.h, constraints/strain_limit_curvature.h).
#include "constraints/singular_value_hessian.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include "constraints/strain_limit_curvature.h"
#include "tests/test_utils.h"

namespace taut {
namespace {

const double kHessianInf = std::numeric_limits<double>::infinity();
constexpr StrainProjection kAllModes[] = {
    StrainProjection::kHyperbolic, StrainProjection::kOrthogonal,
    StrainProjection::kLinearInterpolation, StrainProjection::kEllipsoid};

using testing::RandomRotation;

// Signed values in [0.5, 1.5], gaps >= 0.1, s_3 < 0 (inverted) a quarter of the time.
Vec3 RandomSeparatedValues(std::mt19937* rng) {
  return testing::RandomSeparatedSignedValues(*rng, 0.5, 1.5, 0.25);
}

// A perturbed regular rest tet: rows r_n and rest nodes X.
TetRestRows MakeRestRows(std::mt19937* rng, std::array<Vec3, 4>* X_out) {
  std::uniform_real_distribution<double> u(-0.15, 0.15);
  std::array<Vec3, 4> X = {Vec3(1, 1, 1), Vec3(1, -1, -1), Vec3(-1, 1, -1), Vec3(-1, -1, 1)};
  for (Vec3& p : X) p = 0.3 * (p + Vec3(u(*rng), u(*rng), u(*rng)));
  Mat3 X0;
  for (int c = 0; c < 3; ++c) X0.col(c) = X[c] - X[3];
  const Mat3 inv = X0.inverse();
  TetRestRows r;
  for (int n = 0; n < 3; ++n) r[n] = inv.row(n).transpose();
  r[3] = -(r[0] + r[1] + r[2]);
  *X_out = X;
  return r;
}

// ds_i/dF = u_i v_i^T (paper A eq. 13 in F space), row-major 9-vector.
Eigen::Matrix<double, 9, 1> GradientOfSingularValue(const Mat3& F, int i) {
  const SignedSvd svd = CalcSignedSvd(F);
  const Mat3 g = svd.U.col(i) * svd.V.col(i).transpose();
  Eigen::Matrix<double, 9, 1> out;
  for (int k = 0; k < 3; ++k)
    for (int l = 0; l < 3; ++l) out[3 * k + l] = g(k, l);
  return out;
}

// The analytic Hessian of s_i against central differences of the analytic gradient u_i v_i^T,
// unclamped (epsilon = 0), on well-separated and inverted states.
TEST(SingularValueHessianTest, MatchesFdOfTheGradient) {
  std::mt19937 rng(1);
  double worst = 0.0;
  for (int trial = 0; trial < 300; ++trial) {
    const Vec3 s = RandomSeparatedValues(&rng);
    const Mat3 F = RandomRotation(rng) * s.asDiagonal() * RandomRotation(rng).transpose();
    const SignedSvd svd = CalcSignedSvd(F);
    for (int i = 0; i < 3; ++i) {
      const Mat9 H = CalcDenseSingularValueHessian(CalcSingularValueHessian(svd, i, 0.0));
      Mat9 H_fd;
      const double h = 1e-6;
      for (int c = 0; c < 9; ++c) {
        Mat3 dF = Mat3::Zero();
        dF(c / 3, c % 3) = h;
        H_fd.col(c) =
            (GradientOfSingularValue(F + dF, i) - GradientOfSingularValue(F - dF, i)) / (2.0 * h);
      }
      ASSERT_GT(H_fd.norm(), 1e-2);
      worst = std::max(worst, (H - H_fd).norm() / H_fd.norm());
      // Symmetric, zero on the diagonal modes u_k v_k^T.
      EXPECT_LT((H - H.transpose()).norm(), 1e-12 * H.norm());
      for (int k = 0; k < 3; ++k) {
        const Mat3 M = svd.U.col(k) * svd.V.col(k).transpose();
        Eigen::Matrix<double, 9, 1> m;
        for (int a = 0; a < 3; ++a)
          for (int b = 0; b < 3; ++b) m[3 * a + b] = M(a, b);
        EXPECT_LT((H * m).norm(), 1e-10 * H.norm());
      }
    }
  }
  std::printf("[ d2 s_i / dF2 vs FD of u_i v_i^T ] max rel err %.2e\n", worst);
  EXPECT_LT(worst, 1e-6);
}

// Eigenvalues are 1/(s_i - s_j) and 1/(s_i + s_j); the modes are orthonormal.
TEST(SingularValueHessianTest, EigenvaluesAreTheInverseGaps) {
  const Vec3 s(1.4, 1.1, -0.6);
  std::mt19937 rng(2);
  const SignedSvd svd =
      CalcSignedSvd(RandomRotation(rng) * s.asDiagonal() * RandomRotation(rng).transpose());
  const SingularValueHessian hessian = CalcSingularValueHessian(svd, 1, 0.0);
  EXPECT_NEAR(hessian.eigenvalues[0], 1.0 / (1.1 - 1.4), 1e-9);
  EXPECT_NEAR(hessian.eigenvalues[1], 1.0 / (1.1 + 1.4), 1e-9);
  EXPECT_NEAR(hessian.eigenvalues[2], 1.0 / (1.1 + 0.6), 1e-9);
  EXPECT_NEAR(hessian.eigenvalues[3], 1.0 / (1.1 - 0.6), 1e-9);
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b)
      EXPECT_NEAR((hessian.modes[a].array() * hessian.modes[b].array()).sum(), a == b ? 1.0 : 0.0,
                  1e-12);
}

// Isotropic ellipsoid rows C = 1 -+ kappa (s_i - 1) and the floor rows C = (s_i - s_floor) /
// (1 - s_floor) have no frame term, so -d^2C/dx^2 is exactly -+ dC/ds_i d^2 s_i/dx^2: the
// node-space assembly against central differences of the row's J.
TEST(SingularValueHessianTest, NodeAssemblyMatchesFdOfTheRowJacobian) {
  std::mt19937 rng(3);
  StrainLimitSettings settings = StrainLimitSettings::Isotropic(0.9, 1.1);
  settings.svd_gap_epsilon = 0.0;
  settings.activation_margin = kHessianInf;
  const StrainLimitParams params = CalcStrainLimitParams(settings);
  double worst = 0.0;
  int checked = 0;
  for (int trial = 0; trial < 200; ++trial) {
    std::array<Vec3, 4> X;
    const TetRestRows r = MakeRestRows(&rng, &X);
    const Mat3 G = RandomRotation(rng) * RandomSeparatedValues(&rng).asDiagonal() *
                   RandomRotation(rng).transpose();
    TetPositions x;
    for (int n = 0; n < 4; ++n) x[n] = G * X[n];
    const Mat3 Q = RandomRotation(rng);
    std::vector<StrainLimitRow> rows;
    AppendStrainLimitRows(0, r, x, Q, params, &rows);
    const SignedSvd svd = CalcSignedSvd(G);
    for (const StrainLimitRow& row : rows) {
      // -dJ/dx by central differences (the key's row at the perturbed states).
      Mat12 H_fd;
      const double h = 1e-6;
      for (int c = 0; c < 12; ++c) {
        TetPositions xp = x, xm = x;
        xp[c / 3][c % 3] += h;
        xm[c / 3][c % 3] -= h;
        std::vector<StrainLimitRow> rp, rm;
        AppendStrainLimitRows(0, r, xp, Q, params, &rp);
        AppendStrainLimitRows(0, r, xm, Q, params, &rm);
        const auto find = [&](const std::vector<StrainLimitRow>& list) {
          for (const StrainLimitRow& other : list)
            if (other.key == row.key) return other.J;
          ADD_FAILURE() << "key lost under a perturbation";
          return Vec12(Vec12::Zero());
        };
        H_fd.col(c) = -(find(rp) - find(rm)) / (2.0 * h);
      }
      // -dC/ds_i: kappa = 10 on the limit rows, 1 / (1 - s_floor) on the floor rows (C increases
      // with s_i on the lower bound and the floor, decreases on the upper bound).
      const double kappa =
          row.key.axis == kStrainFloorAxis ? 1.0 / (1.0 - params.inversion_floor) : 10.0;
      const double scale = row.key.bound == StrainBound::kMax ? kappa : -kappa;
      const int i = row.principal_index;
      const Mat12 H = CalcTetSingularValueHessian(CalcSingularValueHessian(svd, i, 0.0), r, scale,
                                                  /*clamp_negative=*/false);
      ASSERT_GT(H_fd.norm(), 1e-3);
      worst = std::max(worst, (H - H_fd).norm() / H_fd.norm());
      ++checked;
      // The row curvature is its positive semi-definite part.
      const Mat12 clamped = CalcStrainLimitRowCurvature(r, svd, Q, params, row.key);
      const Mat12 expected = CalcTetSingularValueHessian(CalcSingularValueHessian(svd, i, 0.0), r,
                                                         scale, /*clamp_negative=*/true);
      EXPECT_LT((clamped - expected).norm(), 1e-9 * (1.0 + expected.norm()));
    }
  }
  std::printf("[ -d2C/dx2 node assembly vs FD of J ] %d rows, max rel err %.2e\n", checked, worst);
  EXPECT_GT(checked, 300);
  EXPECT_LT(worst, 1e-6);
}

// Smallest eigenvalue of a symmetric matrix.
double MinEigenvalue(const Mat12& H) {
  return Eigen::SelfAdjointEigenSolver<Mat12>(H, Eigen::EigenvaluesOnly).eigenvalues()[0];
}

// Clamped row curvature of every mode: PSD (eigenvalues >= -1e-12 ||H||) and bounded at
// near-repeated values (s_1 = s_2 + delta, and an inverted pair s_2 = -s_3 + delta) by the
// gap clamp, where the exact Hessian grows like 1/delta.
TEST(SingularValueHessianTest, ClampedCurvatureIsPsdAndBounded) {
  std::mt19937 rng(4);
  double worst_ratio = 0.0, largest = 0.0;
  int checked = 0;
  for (const StrainProjection mode : kAllModes) {
    StrainLimitSettings settings =
        StrainLimitSettings::PerAxis(Vec3(0.8, 0.0, 0.9), Vec3(1.05, 1.3, kHessianInf), mode);
    settings.activation_margin = kHessianInf;
    settings.hyperbolic_row_band = kHessianInf;
    settings.svd_gap_epsilon = 1e-2;  // a coarse clamp: active for most of the deltas below
    const StrainLimitParams params = CalcStrainLimitParams(settings);
    for (int trial = 0; trial < 300; ++trial) {
      std::array<Vec3, 4> X;
      const TetRestRows r = MakeRestRows(&rng, &X);
      const double delta = std::pow(10.0, -1.0 - (trial % 8));
      Vec3 s = RandomSeparatedValues(&rng);
      if (trial % 3 == 1) s[1] = s[0] - delta;
      if (trial % 3 == 2) s = Vec3(1.3, 0.7, -0.7 + delta);
      const Mat3 G = RandomRotation(rng) * s.asDiagonal() * RandomRotation(rng).transpose();
      TetPositions x;
      for (int n = 0; n < 4; ++n) x[n] = G * X[n];
      const Mat3 Q = RandomRotation(rng);
      std::vector<StrainLimitRow> rows;
      AppendStrainLimitRows(0, r, x, Q, params, &rows);
      const SignedSvd svd = CalcSignedSvd(G);
      double r_scale = 0.0;
      for (const Vec3& rn : r) r_scale += rn.squaredNorm();
      for (const StrainLimitRow& row : rows) {
        const Mat12 H = CalcStrainLimitRowCurvature(r, svd, Q, params, row.key);
        ASSERT_TRUE(H.allFinite());
        EXPECT_LT((H - H.transpose()).norm(), 1e-12 * (1.0 + H.norm()));
        const double norm = H.norm();
        if (norm > 0.0) worst_ratio = std::min(worst_ratio, MinEigenvalue(H) / norm);
        // Bound: kappa_eff (<= 20 here, LI <= 1/0.05) times 1/rho (<= 2 |s|max / epsilon)
        // times sum ||r_n||^2, a few modes.
        const double bound = 4.0 * 20.0 * (2.0 * 1.5 / params.svd_gap_epsilon) * r_scale;
        largest = std::max(largest, norm / bound);
        EXPECT_LT(norm, bound) << GetStrainProjectionName(mode) << " delta " << delta;
        ++checked;
      }
    }
  }
  std::printf("[ clamped curvature ] %d rows, min eig / norm %.2e, max norm / bound %.2e\n",
              checked, worst_ratio, largest);
  EXPECT_GT(checked, 1000);
  EXPECT_GE(worst_ratio, -1e-12);
}

// Away from the clamp (gaps above rho) the clamped eigenvalues equal the exact ones.
TEST(SingularValueHessianTest, GapClampOnlyActsOnSmallGaps) {
  std::mt19937 rng(5);
  const Mat3 R = RandomRotation(rng), S = RandomRotation(rng);
  const SignedSvd wide = CalcSignedSvd(R * Vec3(1.3, 1.0, 0.7).asDiagonal() * S.transpose());
  const SingularValueHessian exact = CalcSingularValueHessian(wide, 0, 0.0);
  const SingularValueHessian clamped = CalcSingularValueHessian(wide, 0, 1e-2);
  for (int k = 0; k < 4; ++k) EXPECT_EQ(exact.eigenvalues[k], clamped.eigenvalues[k]);
  const SignedSvd close =
      CalcSignedSvd(R * Vec3(1.0 + 1e-9, 1.0, 0.7).asDiagonal() * S.transpose());
  const SingularValueHessian bounded = CalcSingularValueHessian(close, 0, 1e-2);
  // |s_1 - s_2| -> rho = 1e-2 / (|s_1| + |s_2|) = 5e-3: eigenvalue 200, not 1e9.
  EXPECT_NEAR(bounded.eigenvalues[0], 2.0 / 1e-2, 1e-3);
  EXPECT_NEAR(bounded.eigenvalues[1], 1.0 / 2.0, 1e-8);
}

}  // namespace
}  // namespace taut
