// The full curvature of frame-dependent strain rows (constraints/strain_frame_curvature.h):
// against central differences of the exact row Jacobian and second differences of the row value,
// on random well-separated and inverted states, for hyperbolic and unequal ellipsoid limits.
#include "constraints/strain_frame_curvature.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "tests/test_utils.h"

namespace taut {
namespace {

using testing::RandomRotation;

// Signed values in [0.6, 1.4], gaps >= 0.1, s_3 < 0 a fifth of the time.
Vec3 RandomFrameTestValues(std::mt19937* rng) {
  return testing::RandomSeparatedSignedValues(*rng, 0.6, 1.4, 0.2);
}

// A regular rest tet scaled by 0.3: rows r_n of the inverse edge matrix, rest nodes X.
TetRestRows MakeFrameTestRest(std::array<Vec3, 4>* X) {
  *X = {Vec3(0.3, 0.3, 0.3), Vec3(0.3, -0.3, -0.3), Vec3(-0.3, 0.3, -0.3), Vec3(-0.3, -0.3, 0.3)};
  Mat3 X0;
  for (int c = 0; c < 3; ++c) X0.col(c) = (*X)[c] - (*X)[3];
  const Mat3 inv = X0.inverse();
  TetRestRows r;
  for (int n = 0; n < 3; ++n) r[n] = inv.row(n).transpose();
  r[3] = -(r[0] + r[1] + r[2]);
  return r;
}

StrainLimitParams MakeFrameTestParams(StrainProjection projection) {
  StrainLimitParams params;
  params.projection = projection;
  params.kappa_max = Vec3(0.0, 2.0, 5.0);
  params.kappa_min = Vec3(1.5, 0.0, 3.0);
  params.has_max = params.has_min = true;
  params.activation_margin = 1e9;    // emit every row
  params.hyperbolic_row_band = 1e9;  // every (j, i), not only the dominant one
  params.svd_gap_epsilon = 1e-6;     // inactive at these gaps
  params.full_frame_curvature = true;
  return params;
}

TetPositions DisplaceFrameTestNodes(const TetPositions& x, const Vec12& dx) {
  TetPositions out = x;
  for (int n = 0; n < 4; ++n) out[n] += dx.segment<3>(3 * n);
  return out;
}

const StrainLimitRow* FindFrameTestRow(const std::vector<StrainLimitRow>& rows,
                                       const StrainLimitKey& key) {
  for (const StrainLimitRow& row : rows)
    if (row.key == key) return &row;
  return nullptr;
}

// A state with node positions x_n = F X_n (so G = F), its rows and its limit frame.
struct FrameTestState {
  TetRestRows r;
  TetPositions x;
  Mat3 Q;
  std::vector<StrainLimitRow> rows;
};

FrameTestState MakeFrameTestState(std::mt19937* rng, const StrainLimitParams& params) {
  FrameTestState state;
  std::array<Vec3, 4> X;
  state.r = MakeFrameTestRest(&X);
  const Mat3 F = RandomRotation(*rng) * RandomFrameTestValues(rng).asDiagonal() *
                 RandomRotation(*rng).transpose();
  for (int n = 0; n < 4; ++n) state.x[n] = F * X[n];
  state.Q = RandomRotation(*rng);
  AppendStrainLimitRows(0, state.r, state.x, state.Q, params, &state.rows);
  return state;
}

// Rows whose frame factor is far from the hyperbolic |V'_ji| kink (there C is not C^2).
bool IsAwayFromKink(const FrameTestState& state, const StrainLimitParams& params,
                    const StrainLimitRow& row) {
  // Floor rows (kStrainFloorAxis) are functions of s_i alone: no frame factor, no kink.
  if (params.projection != StrainProjection::kHyperbolic || row.key.axis == kStrainFloorAxis)
    return true;
  const SignedSvd svd = CalcSignedSvd(CalcTetDeformationGradient(state.r, state.x));
  const Mat3 V_prime = state.Q.transpose() * svd.V;
  return std::abs(V_prime(row.key.axis, row.principal_index)) > 0.05;
}

class StrainFrameCurvatureTest : public ::testing::TestWithParam<StrainProjection> {};

// -d^2 C/dx^2 against -dJ/dx by central differences of the exact Jacobian (dV/dx included).
TEST_P(StrainFrameCurvatureTest, MatchesFdOfTheRowJacobian) {
  const StrainLimitParams params = MakeFrameTestParams(GetParam());
  std::mt19937 rng(7);
  double worst = 0.0;
  int checked = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const FrameTestState state = MakeFrameTestState(&rng, params);
    const SignedSvd svd = CalcSignedSvd(CalcTetDeformationGradient(state.r, state.x));
    for (const StrainLimitRow& row : state.rows) {
      if (!IsAwayFromKink(state, params, row)) continue;
      const Mat12 H = MapPrincipalHessianToTet(
          CalcPrincipalStrainRowCurvature(svd, state.Q, params, row.key), svd, state.r);
      Mat12 fd;
      bool matched = true;
      const double t = 1e-6;
      for (int k = 0; k < 12 && matched; ++k) {
        std::vector<StrainLimitRow> plus, minus;
        AppendStrainLimitRows(0, state.r, DisplaceFrameTestNodes(state.x, t * Vec12::Unit(k)),
                              state.Q, params, &plus);
        AppendStrainLimitRows(0, state.r, DisplaceFrameTestNodes(state.x, -t * Vec12::Unit(k)),
                              state.Q, params, &minus);
        const StrainLimitRow* p = FindFrameTestRow(plus, row.key);
        const StrainLimitRow* m = FindFrameTestRow(minus, row.key);
        matched = p != nullptr && m != nullptr;
        if (matched) fd.col(k) = -(p->J - m->J) / (2.0 * t);
      }
      if (!matched) continue;
      worst = std::max(worst, (H - fd).cwiseAbs().maxCoeff() / std::max(1.0, fd.norm()));
      ++checked;
    }
  }
  EXPECT_GT(checked, 200);
  EXPECT_LT(worst, 1e-5);
}

// d^2 C along random directions against second differences of the row value C alone.
TEST_P(StrainFrameCurvatureTest, MatchesSecondDifferencesOfTheRowValue) {
  const StrainLimitParams params = MakeFrameTestParams(GetParam());
  std::mt19937 rng(11);
  std::normal_distribution<double> n(0.0, 1.0);
  double worst = 0.0;
  int checked = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const FrameTestState state = MakeFrameTestState(&rng, params);
    const SignedSvd svd = CalcSignedSvd(CalcTetDeformationGradient(state.r, state.x));
    Vec12 d;
    for (int k = 0; k < 12; ++k) d[k] = n(rng);
    const double t = 2e-5;  // truncation O(t^2) and round-off O(eps / t^2) both below 1e-5
    std::vector<StrainLimitRow> plus, minus;
    AppendStrainLimitRows(0, state.r, DisplaceFrameTestNodes(state.x, t * d), state.Q, params,
                          &plus);
    AppendStrainLimitRows(0, state.r, DisplaceFrameTestNodes(state.x, -t * d), state.Q, params,
                          &minus);
    for (const StrainLimitRow& row : state.rows) {
      if (!IsAwayFromKink(state, params, row)) continue;
      const StrainLimitRow* p = FindFrameTestRow(plus, row.key);
      const StrainLimitRow* m = FindFrameTestRow(minus, row.key);
      if (p == nullptr || m == nullptr) continue;
      const Mat12 H = MapPrincipalHessianToTet(
          CalcPrincipalStrainRowCurvature(svd, state.Q, params, row.key), svd, state.r);
      const double second_difference = (p->C - 2.0 * row.C + m->C) / (t * t);
      const double analytic = -d.dot(H * d);
      worst = std::max(worst,
                       std::abs(analytic - second_difference) / std::max(1.0, std::abs(analytic)));
      ++checked;
    }
  }
  EXPECT_GT(checked, 200);
  EXPECT_LT(worst, 1e-4);
}

INSTANTIATE_TEST_SUITE_P(FrameDependentRows, StrainFrameCurvatureTest,
                         ::testing::Values(StrainProjection::kHyperbolic,
                                           StrainProjection::kEllipsoid));

// With equal weights the frame factor is constant, and the curvature is kappa times that of s_i
// (constraints/singular_value_hessian.h), so the frame terms add nothing there.
TEST(StrainFrameCurvatureIsotropicTest, ReducesToTheStretchCurvature) {
  StrainLimitParams params = MakeFrameTestParams(StrainProjection::kEllipsoid);
  params.kappa_max = Vec3::Constant(4.0);
  params.kappa_min = Vec3::Constant(2.0);
  EXPECT_FALSE(HasStrainFrameCurvature(params));
  // ... so the stretch curvature alone is exact (the primal path's model steps rely on it); the
  // orthogonal projection's rows depend on the frame without a frame term.
  EXPECT_TRUE(HasExactStrainCurvature(params));
  StrainLimitParams orthogonal = params;
  orthogonal.projection = StrainProjection::kOrthogonal;
  EXPECT_FALSE(HasExactStrainCurvature(orthogonal));
  std::mt19937 rng(5);
  double worst = 0.0;
  for (int trial = 0; trial < 100; ++trial) {
    const FrameTestState state = MakeFrameTestState(&rng, params);
    const SignedSvd svd = CalcSignedSvd(CalcTetDeformationGradient(state.r, state.x));
    for (const StrainLimitRow& row : state.rows) {
      const bool is_max = row.key.bound == StrainBound::kMax;
      // sigma kappa; the floor rows: -1 / (1 - s_floor) (docs/math.md §3.8).
      const double scale = row.key.axis == kStrainFloorAxis ? -1.0 / (1.0 - params.inversion_floor)
                           : is_max                         ? 4.0
                                                            : -2.0;
      const Mat12 expected = CalcTetSingularValueHessian(
          CalcSingularValueHessian(svd, row.principal_index, params.svd_gap_epsilon), state.r,
          scale, /*clamp_negative=*/false);
      const Mat12 H = MapPrincipalHessianToTet(
          CalcPrincipalStrainRowCurvature(svd, state.Q, params, row.key), svd, state.r);
      worst =
          std::max(worst, (H - expected).cwiseAbs().maxCoeff() / std::max(1.0, expected.norm()));
    }
  }
  EXPECT_LT(worst, 1e-12);
}

TEST(StrainFrameCurvatureClampTest, KeepsThePositivePartOnly) {
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    Mat9 A;
    for (int k = 0; k < 81; ++k) A.data()[k] = n(rng);
    const Mat9 H = A + A.transpose();
    const Mat9 clamped = ClampNegativeModes(H);
    const Eigen::SelfAdjointEigenSolver<Mat9> of_clamped(clamped), of_rest(H - clamped);
    EXPECT_GT(of_clamped.eigenvalues().minCoeff(), -1e-12);  // PSD
    EXPECT_LT(of_rest.eigenvalues().maxCoeff(), 1e-12);      // only negative modes removed
    const Mat9 psd = A * A.transpose();
    EXPECT_LT((ClampNegativeModes(psd) - psd).cwiseAbs().maxCoeff(), 1e-10 * psd.norm());
    // Rank 4 (five zero modes) and one mode just below zero: both kept by the Cholesky screen;
    // a mode at -1e-6 of the scale is clamped.
    const Eigen::Matrix<double, 9, 4> B = A.leftCols<4>();
    const Mat9 rank4 = B * B.transpose();
    EXPECT_TRUE(ClampNegativeModes(rank4) == rank4);
    const Eigen::Matrix<double, 9, 1> u = A.col(5).normalized();
    const double scale = rank4.diagonal().maxCoeff();
    const Mat9 slightly = rank4 - 1e-12 * scale * u * u.transpose();
    EXPECT_TRUE(ClampNegativeModes(slightly) == slightly);
    const Mat9 negative = rank4 - 1e-6 * scale * u * u.transpose();
    const Eigen::SelfAdjointEigenSolver<Mat9> of_negative(ClampNegativeModes(negative));
    EXPECT_GT(of_negative.eigenvalues().minCoeff(), -1e-12 * scale);
  }
}

// With kept_fraction f, a sum whose eigenvalues all exceed -f max |H_kk| is kept whole (the
// source keeps the frame curvature's mildly indefinite element sums, docs/math.md §5.9); one with
// a mode below that is clamped to its PSD part.
TEST(StrainFrameCurvatureClampTest, KeepsModesAboveTheKeptFraction) {
  std::mt19937 rng(11);
  std::normal_distribution<double> n;
  Mat9 A;
  for (int k = 0; k < 81; ++k) A.data()[k] = n(rng);
  const Eigen::HouseholderQR<Mat9> qr(A);
  const Mat9 Q = qr.householderQ();
  using Vec9 = Eigen::Matrix<double, 9, 1>;
  Vec9 mild = Vec9::Ones(), strong = Vec9::Ones();
  mild[8] = -0.2;    // max |H_kk| >= 0.4 (a convex combination of the eigenvalues, mostly 1)
  strong[8] = -0.9;  // below -0.5 max |H_kk| (max |H_kk| <= 1)
  const Mat9 H_mild = Q * mild.asDiagonal() * Q.transpose();
  const Mat9 H_strong = Q * strong.asDiagonal() * Q.transpose();
  ASSERT_GT(H_mild.diagonal().cwiseAbs().maxCoeff(), 0.4);
  EXPECT_TRUE(ClampNegativeModes(H_mild, kFrameCurvatureKeptNegativeFraction) == H_mild);
  EXPECT_FALSE(ClampNegativeModes(H_mild) == H_mild);  // the exact clamp removes -0.2
  const Mat9 clamped = ClampNegativeModes(H_strong, kFrameCurvatureKeptNegativeFraction);
  Vec9 psd = strong;
  psd[8] = 0.0;
  EXPECT_LT((clamped - Q * psd.asDiagonal() * Q.transpose()).norm(), 1e-12);
}

// The factored map (two 3x3 frames) against the product W^T H W with W = dvec(P)/dx written out:
// W((x, y), (n, k)) = U_kx (V^T r_n)_y, P indexed 3 x + y.
TEST(StrainFrameCurvatureMapTest, EqualsTheDenseChainRuleProduct) {
  std::mt19937 rng(5);
  std::normal_distribution<double> n;
  std::array<Vec3, 4> X;
  const TetRestRows r = MakeFrameTestRest(&X);
  for (int trial = 0; trial < 50; ++trial) {
    Mat9 A;
    for (int k = 0; k < 81; ++k) A.data()[k] = n(rng);
    const Mat9 H = A + A.transpose();
    SignedSvd svd;
    svd.U = RandomRotation(rng);
    svd.V = RandomRotation(rng);
    svd.s = RandomFrameTestValues(&rng);
    Eigen::Matrix<double, 9, 12> W;
    for (int node = 0; node < 4; ++node) {
      const Vec3 r_hat = svd.V.transpose() * r[node];
      for (int k = 0; k < 3; ++k)
        for (int x = 0; x < 3; ++x)
          for (int y = 0; y < 3; ++y) W(3 * x + y, 3 * node + k) = svd.U(k, x) * r_hat[y];
    }
    const Mat12 expected = W.transpose() * H * W;
    const Mat12 mapped = MapPrincipalHessianToTet(H, svd, r);
    EXPECT_LT((mapped - expected).cwiseAbs().maxCoeff(), 1e-12 * expected.norm());
    EXPECT_LT((mapped - mapped.transpose()).cwiseAbs().maxCoeff(), 1e-12 * expected.norm());
  }
}

}  // namespace
}  // namespace taut
