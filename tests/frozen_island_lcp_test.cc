// FrozenIslandLcp (constraints/frozen_island_lcp.h) on problems solved by hand.
#include "constraints/frozen_island_lcp.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace taut {
namespace {

ToolTwist Lin(double x, double y, double z) {
  ToolTwist u = ToolTwist::Zero();
  u.head<3>() = Vec3(x, y, z);
  return u;
}

PgsSettings Tight() {
  PgsSettings settings;
  settings.tolerance = 1e-14;
  settings.max_sweeps = 200;
  return settings;
}

// One contact row, W = 2, q0 = -1, J_t = [-1 0 0 | 0 0 0] (the tool on the row's far side along
// x): lambda = max(0, (1 + u_x) / 2) by hand, and the tool gets J_t^T lambda = -lambda along x.
TEST(FrozenIslandLcpTest, OneContactRowByHand) {
  ToolJacobian J_t = ToolJacobian::Zero(1, 6);
  J_t(0, 0) = -1.0;
  FrozenIslandLcp lcp(MatX::Constant(1, 1, 2.0), VecX::Constant(1, -1.0), {MakeUnilateralRow()},
                      VecX::Constant(1, 0.5), J_t);
  // No motion: lambda0 is the solution already.
  FrozenIslandLcp::Result r = lcp.Solve(ToolTwist::Zero(), Tight());
  EXPECT_NEAR(lcp.lambda()[0], 0.5, 1e-14);
  EXPECT_NEAR(r.impulse[0], -0.5, 1e-14);
  EXPECT_LE(r.pgs.sweeps, 1);
  // The tool pushes in (u_x = 1 closes the row at 1 m/s more): lambda = 1.
  r = lcp.Solve(Lin(1.0, 0.0, 0.0), Tight());
  EXPECT_NEAR(lcp.lambda()[0], 1.0, 1e-14);
  // The tool pulls away past separation: lambda = 0, no force.
  r = lcp.Solve(Lin(-2.0, 0.0, 0.0), Tight());
  EXPECT_EQ(lcp.lambda()[0], 0.0);
  EXPECT_TRUE(r.impulse.isZero(0.0));
  // Warm start back to lambda0.
  lcp.ResetWarmStart();
  EXPECT_EQ(lcp.lambda()[0], 0.5);
}

// A contact with a friction pair, W = I: lambda_n = -q_n; a tangential pull of 2 with mu = 0.5
// slides: lambda_t on the disk's rim opposite the slip, (0.5, 0) for q_t = (-2, 0).
TEST(FrozenIslandLcpTest, FrictionPairSlidesOnTheDisk) {
  std::vector<PgsRow> rows(3, MakeUnilateralRow());
  for (int c : {1, 2}) {
    rows[c].kind = RowKind::kFriction;
    rows[c].cone = FrictionCone::kDisk;
    rows[c].normal = 0;
    rows[c].partner = c == 1 ? 2 : 1;
    rows[c].lo = -std::numeric_limits<double>::infinity();
    rows[c].mu = 0.5;
  }
  // J_t moves the normal row by -u_z and the first tangent by -u_x (a tool point's motion).
  ToolJacobian J_t = ToolJacobian::Zero(3, 6);
  J_t(0, 2) = -1.0;
  J_t(1, 0) = -1.0;
  FrozenIslandLcp lcp(MatX::Identity(3, 3), VecX::Constant(3, 0.0), rows, VecX::Zero(3), J_t);
  lcp.Solve(Lin(2.0, 0.0, 1.0), Tight());
  EXPECT_NEAR(lcp.lambda()[0], 1.0, 1e-12);
  EXPECT_NEAR(lcp.lambda()[1], 0.5, 1e-12);
  EXPECT_NEAR(lcp.lambda()[2], 0.0, 1e-12);
  // Sticking: a small pull stays inside the disk, lambda_t = -q_t.
  lcp.Solve(Lin(0.2, 0.0, 1.0), Tight());
  EXPECT_NEAR(lcp.lambda()[1], 0.2, 1e-12);
}

// Stacking two islands shifts the friction rows' indices and keeps W block-diagonal.
TEST(FrozenIslandLcpTest, StackingShiftsRowIndices) {
  FrozenIsland a{MatX::Constant(1, 1, 2.0),
                 VecX::Constant(1, -1.0),
                 {MakeUnilateralRow()},
                 VecX::Constant(1, 0.5)};
  FrozenIsland b = a;
  PgsRow friction;
  friction.kind = RowKind::kFriction;
  friction.cone = FrictionCone::kBox;
  friction.normal = 0;
  friction.mu = 1.0;
  friction.lo = -std::numeric_limits<double>::infinity();
  b.W = MatX::Identity(2, 2);
  b.q0 = VecX::Constant(2, -1.0);
  b.rows = {MakeUnilateralRow(), friction};
  b.lambda0 = VecX::Zero(2);
  const FrozenIslandLcp lcp =
      StackFrozenIslands({a, b}, {ToolJacobian::Zero(1, 6), ToolJacobian::Zero(2, 6)});
  ASSERT_EQ(lcp.size(), 3);
  EXPECT_EQ(lcp.rows()[2].normal, 1);
  EXPECT_EQ(lcp.W()(0, 1), 0.0);
  EXPECT_EQ(lcp.W()(2, 2), 1.0);
  EXPECT_THROW(StackFrozenIslands({a}, {ToolJacobian::Zero(2, 6)}), InputError);
}

TEST(FrozenIslandLcpTest, BadInputThrows) {
  EXPECT_THROW(FrozenIslandLcp(MatX::Constant(1, 1, 2.0), VecX::Constant(1, -1.0),
                               {MakeUnilateralRow()}, VecX::Zero(1), ToolJacobian::Zero(2, 6)),
               InputError);
  FrozenIslandLcp lcp(MatX::Constant(1, 1, 2.0), VecX::Constant(1, -1.0), {MakeUnilateralRow()},
                      VecX::Zero(1), ToolJacobian::Zero(1, 6));
  ToolTwist bad = ToolTwist::Zero();
  bad[3] = std::nan("");
  EXPECT_THROW(lcp.Solve(bad, PgsSettings()), InputError);
}

}  // namespace
}  // namespace taut
