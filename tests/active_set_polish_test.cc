// Tests of the active-set polish (constraints/active_set_polish.h): from a rough PGS answer it
// solves unilateral LCPs whose rows differ in scale by up to 1e9 (an island's contact rows in m
// next to strain rows of small elements), with rank-deficient W, and never raises the objective.
#include "constraints/active_set_polish.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

namespace taut {
namespace {

// A unilateral LCP with a known solution (lambda0, w0 complementary, q = w0 - W lambda0) for
// W = J J^T of rank `rank` < m, then every row c rescaled by s_c: W' = S W S, q' = S q, whose
// solution is lambda0' = S^-1 lambda0, w0' = S w0. s_c spans 1e-3 .. 1e3 (W'_cc over 1e12).
struct ScaledLcp {
  MatX W;
  VecX q, lambda0, w0, scale;
};
ScaledLcp MakeScaledRankDeficientLcp(int m, int rank, std::mt19937* rng) {
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> uniform(0.1, 1.0), exponent(-2.5, 2.5);
  MatX J(m, rank);
  for (int i = 0; i < m; ++i)
    for (int k = 0; k < rank; ++k) J(i, k) = normal(*rng) / std::sqrt(rank);
  const MatX W = J * J.transpose();
  VecX lambda0 = VecX::Zero(m), w0 = VecX::Zero(m), scale(m);
  // Positive multipliers only where W's range allows it: lambda0 on the first `rank` rows.
  for (int c = 0; c < m; ++c) (c < rank && (*rng)() % 2 ? lambda0[c] : w0[c]) = uniform(*rng);
  const VecX q = w0 - W * lambda0;
  for (int c = 0; c < m; ++c) scale[c] = std::pow(10.0, exponent(*rng));
  scale[0] = std::pow(10.0, -2.5);  // the extremes present in every case
  scale[1] = std::pow(10.0, 2.5);
  ScaledLcp p;
  p.W = scale.asDiagonal() * W * scale.asDiagonal();
  p.q = scale.cwiseProduct(q);
  p.lambda0 = lambda0.cwiseQuotient(scale);
  p.w0 = scale.cwiseProduct(w0);
  p.scale = scale;
  return p;
}

std::vector<PgsRow> UnilateralRows(int m) { return std::vector<PgsRow>(m); }

TEST(ActiveSetPolishTest, SolvesRankDeficientLcpsWhoseRowScalesDifferBy1e9) {
  std::mt19937 rng(7);
  const int m = 30, rank = 20;
  int solved = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const ScaledLcp p = MakeScaledRankDeficientLcp(m, rank, &rng);
    ASSERT_GT(p.W.diagonal().maxCoeff() / p.W.diagonal().minCoeff(), 1e9);
    const std::vector<PgsRow> rows = UnilateralRows(m);
    PgsSettings pgs;
    pgs.max_sweeps = 10;  // a rough start, as a capped PGS leaves it
    pgs.tolerance = 0.0;
    pgs.min_diagonal = 0.0;  // the smallest rows sit below PGS's default skip threshold
    VecX lambda = VecX::Zero(m);
    SolvePgs(p.W, p.q, rows, lambda, pgs);
    const double before = CalcLcpResidual(p.W, p.q, rows, lambda).natural_map;
    PolishActiveSet(p.W, p.q, rows, lambda, pgs, ActiveSetPolishSettings());
    // w = W' lambda + q' is unique for PSD W (lambda need not be): compare it row by row in the
    // unscaled units, w_c / s_c against w0_c / s_c.
    const VecX w = p.W * lambda + p.q;
    const double w_error = (w - p.w0).cwiseQuotient(p.scale).cwiseAbs().maxCoeff();
    double complementarity = 0.0;
    for (int c = 0; c < m; ++c)
      complementarity = std::max(complementarity, std::abs(lambda[c] * w[c]));
    std::printf(
        "trial %2d: natural-map residual %.2e after 10 sweeps, w error %.2e after the "
        "polish\n",
        trial, before, w_error);
    EXPECT_TRUE((lambda.array() >= 0.0).all());
    EXPECT_LT(w_error, 1e-6) << "trial " << trial;
    EXPECT_LT(complementarity, 1e-6) << "trial " << trial;
    solved += w_error < 1e-6 ? 1 : 0;
  }
  EXPECT_EQ(solved, 20);
}

TEST(ActiveSetPolishTest, ObjectiveNeverRises) {
  std::mt19937 rng(11);
  const int m = 24, rank = 12;
  for (int trial = 0; trial < 10; ++trial) {
    const ScaledLcp p = MakeScaledRankDeficientLcp(m, rank, &rng);
    const std::vector<PgsRow> rows = UnilateralRows(m);
    PgsSettings pgs;
    pgs.max_sweeps = 3;
    VecX lambda = VecX::Zero(m);
    SolvePgs(p.W, p.q, rows, lambda, pgs);
    auto objective = [&](const VecX& l) { return 0.5 * l.dot(p.W * l) + p.q.dot(l); };
    const double f_before = objective(lambda);
    PolishActiveSet(p.W, p.q, rows, lambda, pgs, ActiveSetPolishSettings());
    EXPECT_LE(objective(lambda), f_before) << "trial " << trial;
  }
}

}  // namespace
}  // namespace taut
