// Tests of the complementarity-problem rows, projections and residuals
// (constraints/lcp_residual.h).
#include "constraints/lcp_residual.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

namespace taut {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Rows n, t1, t2 of one contact with the given cone.
std::vector<PgsRow> MakeContact(double mu, FrictionCone cone) {
  std::vector<PgsRow> rows;
  AppendContactRows(mu, cone, &rows);
  return rows;
}

// Expects fn to throw InputError whose message contains `part`.
template <typename Fn>
void ExpectInputError(Fn fn, const std::string& part) {
  try {
    fn();
    ADD_FAILURE() << "no InputError (expected one mentioning '" << part << "')";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

TEST(LcpResidualTest, RowFactoriesAndContactIndices) {
  std::vector<PgsRow> rows = {MakeUnilateralRow(), MakeBilateralRow(-2.0, 3.0)};
  EXPECT_EQ(rows[1].kind, RowKind::kBilateral);
  EXPECT_EQ(rows[1].lo, -2.0);
  EXPECT_EQ(rows[1].hi, 3.0);
  EXPECT_EQ(AppendContactRows(0.4, FrictionCone::kDisk, &rows), 2);
  ASSERT_EQ(rows.size(), 5u);
  EXPECT_EQ(rows[2].kind, RowKind::kUnilateral);
  EXPECT_EQ(rows[3].normal, 2);
  EXPECT_EQ(rows[3].partner, 4);
  EXPECT_EQ(rows[4].normal, 2);
  EXPECT_EQ(rows[4].partner, 3);
  EXPECT_EQ(rows[4].mu, 0.4);
  ValidatePgsRows(rows, 5);  // does not throw
}

TEST(LcpResidualTest, CoulombDiskProjection) {
  // Inside: unchanged. Outside: scaled onto the circle of radius mu lambda_n = 1, same direction.
  EXPECT_EQ(ProjectOnCoulombDisk(0.3, -0.4, 0.5, 2.0), Eigen::Vector2d(0.3, -0.4));
  const Eigen::Vector2d p = ProjectOnCoulombDisk(3.0, -4.0, 0.5, 2.0);
  EXPECT_NEAR(p[0], 0.6, 1e-15);
  EXPECT_NEAR(p[1], -0.8, 1e-15);
  // A negative normal impulse gives radius 0.
  EXPECT_EQ(ProjectOnCoulombDisk(3.0, -4.0, 0.5, -1.0), Eigen::Vector2d(0.0, 0.0));
}

TEST(LcpResidualTest, ZeroAtHandSolution) {
  // W = [[2,1],[1,2]], q = (-1,-1): lambda = (1/3, 1/3) gives w = 0.
  MatX W(2, 2);
  W << 2, 1, 1, 2;
  const VecX q = VecX::Constant(2, -1.0);
  const std::vector<PgsRow> rows(2, MakeUnilateralRow());
  const LcpResidual r = CalcLcpResidual(W, q, rows, VecX::Constant(2, 1.0 / 3.0));
  EXPECT_LT(r.natural_map, 1e-15);
  EXPECT_LT(r.complementarity, 1e-15);
  EXPECT_EQ(r.max_violation, 0.0);
}

TEST(LcpResidualTest, UnilateralValuesByHand) {
  MatX W(1, 1);
  W << 2.0;
  const VecX q = VecX::Constant(1, -2.0);
  const std::vector<PgsRow> rows = {MakeUnilateralRow()};
  // lambda = 0: w = -2, r = 0 - max(0, 0 + 2) = -2, violated by 2.
  LcpResidual r = CalcLcpResidual(W, q, rows, VecX::Zero(1));
  EXPECT_DOUBLE_EQ(r.natural_map, 2.0);
  EXPECT_DOUBLE_EQ(r.max_violation, 2.0);
  EXPECT_DOUBLE_EQ(r.min_unilateral_w, -2.0);
  EXPECT_DOUBLE_EQ(r.complementarity, 0.0);
  // lambda = 3: w = 4, r = 3 - max(0, -1) = 3, gap |3 * 4| = 12, no violation.
  r = CalcLcpResidual(W, q, rows, VecX::Constant(1, 3.0));
  EXPECT_DOUBLE_EQ(r.natural_map, 3.0);
  EXPECT_DOUBLE_EQ(r.complementarity, 12.0);
  EXPECT_DOUBLE_EQ(r.max_violation, 0.0);
}

TEST(LcpResidualTest, BilateralBoundSigns) {
  // lambda at hi = 1 may push with w <= 0 (r = 0), not with w > 0 (r = 1 - 0.5).
  const MatX W = MatX::Identity(1, 1);
  const std::vector<PgsRow> rows = {MakeBilateralRow(-1.0, 1.0)};
  const VecX lambda = VecX::Constant(1, 1.0);
  EXPECT_DOUBLE_EQ(CalcLcpResidual(W, VecX::Constant(1, -1.5), rows, lambda).natural_map, 0.0);
  EXPECT_DOUBLE_EQ(CalcLcpResidual(W, VecX::Constant(1, -0.5), rows, lambda).natural_map, 0.5);
  // Interior lambda needs w = 0 exactly: r = w.
  EXPECT_DOUBLE_EQ(
      CalcLcpResidual(W, VecX::Constant(1, -0.7), rows, VecX::Constant(1, 0.5)).natural_map, 0.2);
  // Bilateral rows do not count in the unilateral violation.
  EXPECT_EQ(CalcLcpResidual(W, VecX::Constant(1, -5.0), rows, lambda).max_violation, 0.0);
}

TEST(LcpResidualTest, FrictionDiskNeedsImpulseOppositeToSlip) {
  // W = I, so w = lambda + q; choose q for w_n = 0, w_t = (2, 0), lambda_n = 1, mu = 0.5.
  const MatX W = MatX::Identity(3, 3);
  const std::vector<PgsRow> rows = MakeContact(0.5, FrictionCone::kDisk);
  VecX lambda(3), w(3);
  lambda << 1.0, -0.5, 0.0;
  w << 0.0, 2.0, 0.0;
  EXPECT_LT(CalcLcpResidual(W, w - lambda, rows, lambda).natural_map, 1e-15);
  // Same slip, impulse of full size but rotated 90 degrees: r = lambda_t - Proj(lambda_t - w_t).
  lambda << 1.0, 0.0, -0.5;
  const Eigen::Vector2d proj = ProjectOnCoulombDisk(-2.0, -0.5, 0.5, 1.0);
  const double expected = std::max(std::abs(0.0 - proj[0]), std::abs(-0.5 - proj[1]));
  EXPECT_GT(expected, 0.3);
  EXPECT_DOUBLE_EQ(CalcLcpResidual(W, w - lambda, rows, lambda).natural_map, expected);
}

TEST(LcpResidualTest, BoxConeAcceptsCornerThatDiskRejects) {
  // Diagonal slip w_t = (1, 1) with lambda_t = (-0.5, -0.5) = the box corner for mu lambda_n = 0.5.
  const MatX W = MatX::Identity(3, 3);
  VecX lambda(3), w(3);
  lambda << 1.0, -0.5, -0.5;
  w << 0.0, 1.0, 1.0;
  const VecX q = w - lambda;
  EXPECT_LT(CalcLcpResidual(W, q, MakeContact(0.5, FrictionCone::kBox), lambda).natural_map, 1e-15);
  // Disk: Proj((-1.5, -1.5)) = -0.5 (1, 1) / sqrt(2), so r = 0.5 (1 / sqrt(2) - 1) per axis.
  EXPECT_NEAR(CalcLcpResidual(W, q, MakeContact(0.5, FrictionCone::kDisk), lambda).natural_map,
              0.5 * (1.0 - 1.0 / std::sqrt(2.0)), 1e-15);
}

TEST(LcpResidualTest, ObjectiveByHand) {
  // 1/2 (2 + 2*2 + 2*4) + (-1) = 6 for W = [[2,1],[1,2]], q = (-1, 0), lambda = (1, 2).
  MatX W(2, 2);
  W << 2, 1, 1, 2;
  EXPECT_DOUBLE_EQ(CalcLcpObjective(W, Eigen::Vector2d(-1, 0), Eigen::Vector2d(1, 2)), 6.0);
}

TEST(LcpResidualTest, BadProblemsThrowWithWhereAndWhat) {
  MatX W = MatX::Identity(3, 3);
  const VecX q = VecX::Zero(3);
  const VecX lambda = VecX::Zero(3);
  std::vector<PgsRow> rows = MakeContact(0.5, FrictionCone::kDisk);
  ExpectInputError([&] { CalcLcpResidual(W, VecX::Zero(2), rows, lambda); }, "q has 2");
  ExpectInputError([&] { CalcLcpResidual(MatX::Identity(3, 2), q, rows, lambda); }, "square");
  MatX asym = W;
  asym(0, 2) = 0.1;
  ExpectInputError([&] { CalcLcpResidual(asym, q, rows, lambda); }, "not symmetric");
  VecX q_nan = q;
  q_nan[1] = std::nan("");
  ExpectInputError([&] { CalcLcpResidual(W, q_nan, rows, lambda); }, "q[1]");
  auto bad = rows;
  bad[0].hi = 5.0;
  ExpectInputError([&] { ValidatePgsRows(bad, 3); }, "row 0: a unilateral row");
  bad = rows;
  bad[1].partner = 9;
  ExpectInputError([&] { ValidatePgsRows(bad, 3); }, "row 1: friction partner index 9");
  bad = rows;
  bad[1].mu = 0.7;
  ExpectInputError([&] { ValidatePgsRows(bad, 3); }, "does not pair back");
  bad = rows;
  bad[1].mu = bad[2].mu = -0.1;
  ExpectInputError([&] { ValidatePgsRows(bad, 3); }, "mu = -0.1");
  bad = rows;
  bad[0] = MakeBilateralRow();
  ExpectInputError([&] { ValidatePgsRows(bad, 3); }, "is not unilateral");
  bad = rows;
  bad[1].normal = 7;
  ExpectInputError([&] { ValidatePgsRows(bad, 3); }, "normal index 7");
  ExpectInputError([&] { ValidatePgsRows({MakeBilateralRow(1.0, -1.0)}, 1); }, "bilateral bounds");
  ExpectInputError([&] { ValidatePgsRows({MakeBilateralRow(kInf, kInf)}, 1); }, "bilateral");
  ExpectInputError([&] { ValidatePgsRows(rows, 4); }, "3 rows for a 4 x 4");
}

}  // namespace
}  // namespace taut
