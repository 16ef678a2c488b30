// Tests of the projected Gauss-Seidel solver (constraints/pgs_solver.h): cases solved by hand,
// active-set enumeration, known-solution random LCPs, friction cones, and no heap allocation.
#include "constraints/pgs_solver.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <random>

#include "tests/allocation_counter.h"

namespace taut {
namespace {

using AllocationCounter = testing::ScopedAllocationCounter;

// W = J J^T with J (m x rank) Gaussian / sqrt(rank): PD for rank >= m, PSD-singular otherwise.
MatX MakeRandomPsd(int m, int rank, std::mt19937* rng) {
  std::normal_distribution<double> normal;
  MatX J(m, rank);
  for (int i = 0; i < m; ++i)
    for (int k = 0; k < rank; ++k) J(i, k) = normal(*rng) / std::sqrt(rank);
  return J * J.transpose();
}

// A unilateral LCP with a known solution: random complementary (lambda0, w0), q = w0 - W lambda0.
struct KnownLcp {
  MatX W;
  VecX q, lambda0, w0;
};
KnownLcp MakeKnownLcp(int m, int rank, std::mt19937* rng) {
  std::uniform_real_distribution<double> uniform(0.1, 1.0);
  KnownLcp p{MakeRandomPsd(m, rank, rng), VecX(m), VecX::Zero(m), VecX::Zero(m)};
  for (int c = 0; c < m; ++c) ((*rng)() % 2 ? p.lambda0[c] : p.w0[c]) = uniform(*rng);
  p.q = p.w0 - p.W * p.lambda0;
  return p;
}

// Solves a small unilateral LCP with PD W by enumerating all 2^m active sets.
VecX SolveByEnumeration(const MatX& W, const VecX& q) {
  const int m = static_cast<int>(q.size());
  for (int mask = 0; mask < (1 << m); ++mask) {
    std::vector<int> active;
    for (int c = 0; c < m; ++c)
      if (mask & (1 << c)) active.push_back(c);
    const int a = static_cast<int>(active.size());
    MatX W_aa(a, a);
    VecX q_a(a);
    for (int i = 0; i < a; ++i) {
      q_a[i] = q[active[i]];
      for (int j = 0; j < a; ++j) W_aa(i, j) = W(active[i], active[j]);
    }
    VecX lambda = VecX::Zero(m);
    const VecX lambda_a = W_aa.ldlt().solve(-q_a);
    for (int i = 0; i < a; ++i) lambda[active[i]] = lambda_a[i];
    const VecX w = W * lambda + q;
    if (lambda.minCoeff() >= -1e-12 && w.minCoeff() >= -1e-12) return lambda;
  }
  ADD_FAILURE() << "no active set solves the LCP";
  return VecX::Zero(m);
}

// Settings that run until the natural-map residual reaches `residual` (or max_sweeps).
PgsSettings ResidualSettings(double residual, int max_sweeps) {
  PgsSettings s;
  s.tolerance = 0.0;
  s.residual_tolerance = residual;
  s.max_sweeps = max_sweeps;
  return s;
}

// Delassus matrix of contacts on one rigid body (mass 1, inertia diag(0.1, 0.2, 0.3)) with points
// r_k and frames (z, x, y): rows [d^T, (r x d)^T] M^-1 [d; r x d]. Also q = J v_star.
void MakeRigidContacts(const std::vector<Vec3>& points, const Eigen::Matrix<double, 6, 1>& v_star,
                       MatX* W, VecX* q) {
  const int m = 3 * static_cast<int>(points.size());
  MatX J(m, 6);
  const Vec3 dirs[3] = {Vec3::UnitZ(), Vec3::UnitX(), Vec3::UnitY()};
  for (int k = 0; k < m; ++k) {
    const Vec3& d = dirs[k % 3];
    J.row(k) << d.transpose(), points[k / 3].cross(d).transpose();
  }
  Eigen::Matrix<double, 6, 1> M_inv;
  M_inv << 1, 1, 1, 10, 5, 1.0 / 0.3;
  *W = J * M_inv.asDiagonal() * J.transpose();
  *q = J * v_star;
}

TEST(PgsSolverTest, SingleUnilateralRowActiveAndInactive) {
  MatX W(1, 1);
  W << 4.0;
  const std::vector<PgsRow> rows = {MakeUnilateralRow()};
  VecX lambda = VecX::Zero(1);
  // q < 0: lambda = -q / W = 0.5, found in the first sweep, confirmed (delta 0) in the second.
  PgsStats stats = SolvePgs(W, VecX::Constant(1, -2.0), rows, lambda, PgsSettings{});
  EXPECT_DOUBLE_EQ(lambda[0], 0.5);
  EXPECT_EQ(stats.sweeps, 2);
  EXPECT_TRUE(stats.converged);
  EXPECT_EQ(stats.residual, 0.0);
  // q > 0: lambda = 0 even from a positive warm start.
  lambda[0] = 3.0;
  stats = SolvePgs(W, VecX::Constant(1, 2.0), rows, lambda, PgsSettings{});
  EXPECT_EQ(lambda[0], 0.0);
  EXPECT_EQ(stats.residual, 0.0);
}

TEST(PgsSolverTest, TwoCoupledRowsMatchHandSolutionsAndEnumeration) {
  // W = [[2,1],[1,2]]: both active (lambda = W^-1 (-q)), first only, second only, none.
  MatX W(2, 2);
  W << 2, 1, 1, 2;
  const std::vector<PgsRow> rows(2, MakeUnilateralRow());
  const Eigen::Vector2d qs[4] = {{-1, -1}, {-2, 1}, {-1, -3}, {1, 1}};
  const Eigen::Vector2d expected[4] = {{1.0 / 3, 1.0 / 3}, {1, 0}, {0, 1.5}, {0, 0}};
  for (int k = 0; k < 4; ++k) {
    VecX lambda = VecX::Zero(2);
    const PgsStats stats = SolvePgs(W, qs[k], rows, lambda, ResidualSettings(1e-14, 200));
    EXPECT_TRUE(stats.converged) << "case " << k;
    EXPECT_LT((lambda - expected[k]).norm(), 1e-13) << "case " << k;
    EXPECT_LT((SolveByEnumeration(W, qs[k]) - expected[k]).norm(), 1e-13) << "case " << k;
  }
}

TEST(PgsSolverTest, SmallRandomLcpsMatchEnumeration) {
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  for (int trial = 0; trial < 20; ++trial) {
    const MatX W = MakeRandomPsd(8, 16, &rng);
    VecX q(8);
    for (int c = 0; c < 8; ++c) q[c] = normal(rng);
    VecX lambda = VecX::Zero(8);
    SolvePgs(W, q, std::vector<PgsRow>(8, MakeUnilateralRow()), lambda,
             ResidualSettings(1e-13, 100000));
    EXPECT_LT((lambda - SolveByEnumeration(W, q)).lpNorm<Eigen::Infinity>(), 1e-9) << trial;
  }
}

TEST(PgsSolverTest, OppositeAndIdenticalRowsOfSingularW) {
  // C_min / C_max of one constraint: J and -J, q_1 + q_2 > 0, so only C_min is active.
  MatX W(2, 2);
  W << 1, -1, -1, 1;
  const std::vector<PgsRow> rows(2, MakeUnilateralRow());
  VecX lambda = VecX::Zero(2);
  PgsStats stats = SolvePgs(W, Eigen::Vector2d(-1, 2), rows, lambda, PgsSettings{});
  EXPECT_LT((lambda - Eigen::Vector2d(1, 0)).norm(), 1e-14);
  EXPECT_LT(stats.residual, 1e-14);
  // Two identical rows: any split with lambda_1 + lambda_2 = 1 solves it; no NaN.
  W << 1, 1, 1, 1;
  lambda.setZero();
  stats = SolvePgs(W, Eigen::Vector2d(-1, -1), rows, lambda, PgsSettings{});
  EXPECT_TRUE(lambda.allFinite());
  EXPECT_NEAR(lambda.sum(), 1.0, 1e-14);
  EXPECT_GE(lambda.minCoeff(), 0.0);
  EXPECT_LT(stats.residual, 1e-14);
}

TEST(PgsSolverTest, ZeroDiagonalRowIsSkippedAndReported) {
  MatX W(3, 3);
  W << 2, 0, 1, 0, 0, 0, 1, 0, 2;
  const std::vector<PgsRow> rows(3, MakeUnilateralRow());
  VecX lambda(3);
  lambda << 0, 7, 0;  // the skipped row's stale warm start is reset to 0
  PgsSettings s;
  s.tolerance = 1e-12;
  PgsStats stats = SolvePgs(W, Eigen::Vector3d(-1, 0.5, -1), rows, lambda, s);
  EXPECT_EQ(stats.skipped_rows, 1);
  EXPECT_LT((lambda - Eigen::Vector3d(1.0 / 3, 0, 1.0 / 3)).norm(), 1e-11);
  EXPECT_LT(stats.residual, 1e-11);
  // With q_1 < 0 the skipped row is infeasible and the residual says so.
  stats = SolvePgs(W, Eigen::Vector3d(-1, -0.5, -1), rows, lambda, s);
  EXPECT_EQ(stats.skipped_rows, 1);
  EXPECT_DOUBLE_EQ(stats.residual, 0.5);
}

TEST(PgsSolverTest, WarmStartFromSolutionTakesOneSweep) {
  std::mt19937 rng(3);
  const KnownLcp p = MakeKnownLcp(40, 80, &rng);
  VecX lambda = p.lambda0;
  const PgsStats stats =
      SolvePgs(p.W, p.q, std::vector<PgsRow>(40, MakeUnilateralRow()), lambda, PgsSettings{});
  EXPECT_EQ(stats.sweeps, 1);
  EXPECT_TRUE(stats.converged);
  EXPECT_LT(stats.final_delta, 1e-14);
  EXPECT_LT((lambda - p.lambda0).norm(), 1e-14);
}

TEST(PgsSolverTest, BilateralRowsWithBounds) {
  MatX W(2, 2);
  W << 2, 1, 1, 2;
  // Free rows solve W lambda = -q, also with negative lambda.
  std::vector<PgsRow> rows(2, MakeBilateralRow());
  VecX lambda = VecX::Zero(2);
  SolvePgs(W, Eigen::Vector2d(1, 1), rows, lambda, ResidualSettings(1e-14, 500));
  EXPECT_LT((lambda - Eigen::Vector2d(-1.0 / 3, -1.0 / 3)).norm(), 1e-13);
  // Row 0 in [-1, 1]: the free optimum (8/3, -4/3) clips to lambda_0 = 1, then
  // lambda_1 = -(0 + 1) / 2 and w_0 = 2 - 0.5 - 4 = -2.5 <= 0 is allowed at the upper bound.
  rows[0] = MakeBilateralRow(-1.0, 1.0);
  lambda.setZero();
  const PgsStats stats = SolvePgs(W, Eigen::Vector2d(-4, 0), rows, lambda, PgsSettings{});
  EXPECT_LT((lambda - Eigen::Vector2d(1, -0.5)).norm(), 1e-14);
  EXPECT_LT(stats.residual, 1e-14);
}

TEST(PgsSolverTest, BlockOnPlaneSticksBelowConeAndSlidesAbove) {
  // Point mass m = 2 on z = 0: W = I / m, q = v_star = (v_n, v_t1, v_t2), mu = 0.5, so
  // lambda_n = -m v_n = 2 and the cone radius is 1.
  const MatX W = 0.5 * MatX::Identity(3, 3);
  std::vector<PgsRow> rows;
  AppendContactRows(0.5, FrictionCone::kDisk, &rows);
  // Stick: |m v_t| = 0.447 < 1, lambda_t = -m v_t, w_t = 0.
  VecX lambda = VecX::Zero(3);
  PgsStats stats = SolvePgs(W, Eigen::Vector3d(-1, 0.2, 0.1), rows, lambda, PgsSettings{});
  EXPECT_LT((lambda - Eigen::Vector3d(2, -0.4, -0.2)).norm(), 1e-14);
  EXPECT_LT(stats.residual, 1e-14);
  // Slide: |m v_t| = 4 > 1, lambda_t = -(0.6, 0.8) on the circle, slip w_t = (0.9, 1.2) opposite.
  lambda.setZero();
  stats = SolvePgs(W, Eigen::Vector3d(-1, 1.2, 1.6), rows, lambda, PgsSettings{});
  EXPECT_LT((lambda - Eigen::Vector3d(2, -0.6, -0.8)).norm(), 1e-14);
  const VecX w = W * lambda + Eigen::Vector3d(-1, 1.2, 1.6);
  EXPECT_LT((w - Eigen::Vector3d(0, 0.9, 1.2)).norm(), 1e-14);
  EXPECT_LT(stats.residual, 1e-14);
}

TEST(PgsSolverTest, DiagonalPushDiskVersusBox) {
  // W = I, lambda_n = 1, mu = 0.5, push v_t = (2, 2): the disk gives |lambda_t| = 0.5, the box
  // gives its corner (-0.5, -0.5) with |lambda_t| = sqrt(2) mu lambda_n.
  const MatX W = MatX::Identity(3, 3);
  const Eigen::Vector3d q(-1, 2, 2);
  for (FrictionCone cone : {FrictionCone::kDisk, FrictionCone::kBox}) {
    std::vector<PgsRow> rows;
    AppendContactRows(0.5, cone, &rows);
    VecX lambda = VecX::Zero(3);
    const PgsStats stats = SolvePgs(W, q, rows, lambda, PgsSettings{});
    EXPECT_LT(stats.residual, 1e-14);
    const double t = lambda.tail<2>().norm();
    if (cone == FrictionCone::kDisk) {
      EXPECT_NEAR(t, 0.5, 1e-14);
      EXPECT_NEAR(lambda[1], lambda[2], 1e-14);
    } else {
      EXPECT_NEAR(t, 0.5 * std::sqrt(2.0), 1e-14);
    }
  }
}

TEST(PgsSolverTest, CoupledTangentsSlideOppositeToSlipWithExplicitIndices) {
  // One contact on a rigid body off its center: W_tt is anisotropic and coupled to the normal.
  MatX W;
  VecX q;
  Eigen::Matrix<double, 6, 1> v_star;
  v_star << 1.0, 0.3, -1.0, 0.2, -0.1, 0.5;
  MakeRigidContacts({Vec3(0.3, -0.2, -0.5)}, v_star, &W, &q);
  // Rows stored as (t2, n, t1) to exercise explicit normal / partner indices.
  const Eigen::PermutationMatrix<3> P(Eigen::Vector3i(1, 2, 0));  // new index of n, t1, t2
  const MatX W_p = P * W * P.transpose();
  const VecX q_p = P * q;
  std::vector<PgsRow> rows(3);
  rows[1] = MakeUnilateralRow();
  for (int t : {0, 2}) {
    rows[t].kind = RowKind::kFriction;
    rows[t].lo = -std::numeric_limits<double>::infinity();
    rows[t].normal = 1;
    rows[t].partner = 2 - t;
    rows[t].mu = 0.3;
  }
  VecX lambda = VecX::Zero(3);
  const PgsStats stats = SolvePgs(W_p, q_p, rows, lambda, ResidualSettings(1e-13, 1000));
  ASSERT_TRUE(stats.converged);
  const VecX w = W_p * lambda + q_p;
  const Eigen::Vector2d lambda_t(lambda[2], lambda[0]), w_t(w[2], w[0]);
  EXPECT_GT(lambda[1], 0.1);
  EXPECT_NEAR(w[1], 0.0, 1e-12);
  EXPECT_NEAR(lambda_t.norm(), 0.3 * lambda[1], 1e-12);  // sliding: on the circle
  EXPECT_GT(w_t.norm(), 0.1);
  EXPECT_NEAR(lambda_t.dot(w_t) / (lambda_t.norm() * w_t.norm()), -1.0, 1e-12);
  // Row-wise updates plus a plain disk projection stall away from the solution here.
  VecX naive = VecX::Zero(3);
  for (int s = 0; s < 1000; ++s) {
    for (int c = 0; c < 3; ++c) {
      const double w_c = q_p[c] + W_p.col(c).dot(naive);
      naive[c] = CalcBoxRowUpdate(naive[c], w_c, W_p(c, c), c == 1 ? 0.0 : -1e300, 1e300, 1.0);
    }
    const Eigen::Vector2d t = ProjectOnCoulombDisk(naive[2], naive[0], 0.3, naive[1]);
    naive[2] = t[0];
    naive[0] = t[1];
  }
  EXPECT_GT(CalcLcpResidual(W_p, q_p, rows, naive).natural_map, 1e-3);
}

TEST(PgsSolverTest, CoulombDiskBlockIsTheConstrainedMinimizer) {
  // Compare with a fine search over the circle and the interior solution.
  std::mt19937 rng(11);
  std::normal_distribution<double> normal;
  for (int trial = 0; trial < 50; ++trial) {
    Eigen::Matrix2d J;
    J << normal(rng), normal(rng), normal(rng), normal(rng);
    if (trial % 5 == 0) J.col(1) = 2.0 * J.col(0);  // rank-1 B
    const Eigen::Matrix2d B = J * J.transpose();
    const Eigen::Vector2d g(normal(rng), normal(rng));
    const double radius = 0.05 + std::abs(normal(rng));
    const Eigen::Vector2d x = SolveCoulombDiskBlock(B, g, radius);
    auto f = [&](const Eigen::Vector2d& y) { return 0.5 * y.dot(B * y) + g.dot(y); };
    ASSERT_LE(x.norm(), radius * (1 + 1e-14));
    double best = f(Eigen::Vector2d::Zero());
    for (int k = 0; k < 20000; ++k) {
      const double a = 2 * M_PI * k / 20000;
      best = std::min(best, f(radius * Eigen::Vector2d(std::cos(a), std::sin(a))));
    }
    if (trial % 5 != 0) {
      const Eigen::Vector2d inner = B.ldlt().solve(-g);
      if (inner.norm() <= radius) best = std::min(best, f(inner));
    }
    EXPECT_LE(f(x), best + 1e-12) << trial;
    EXPECT_GE(f(x), best - 1e-6 * (1 + std::abs(best))) << trial;  // grid is within ~1e-7
  }
  // B = 0: the linear objective puts x on the circle opposite to g.
  const Eigen::Vector2d x = SolveCoulombDiskBlock(Eigen::Matrix2d::Zero(), {3, 4}, 2.0);
  EXPECT_LT((x - Eigen::Vector2d(-1.2, -1.6)).norm(), 1e-14);
}

TEST(PgsSolverTest, RandomLcpsReachKnownSolutionsAndReportSweeps) {
  std::mt19937 rng(5);
  std::printf("  m  rank  omega  sweeps to natural-map residual 1e-6 (1e-10)\n");
  for (int m : {20, 50, 100}) {
    for (int rank : {2 * m, m / 2}) {
      const KnownLcp p = MakeKnownLcp(m, rank, &rng);
      const std::vector<PgsRow> rows(m, MakeUnilateralRow());
      for (double omega : {1.0, 1.3}) {
        int sweeps[2];
        VecX lambda = VecX::Zero(m);
        for (int k = 0; k < 2; ++k) {
          PgsSettings s = ResidualSettings(k == 0 ? 1e-6 : 1e-10, 200000);
          s.relaxation = omega;
          const PgsStats stats = SolvePgs(p.W, p.q, rows, lambda, s);
          ASSERT_TRUE(stats.converged) << m << " " << rank;
          sweeps[k] = stats.sweeps + (k == 1 ? sweeps[0] : 0);
        }
        std::printf("%4d %5d %6.1f  %6d (%6d)\n", m, rank, omega, sweeps[0], sweeps[1]);
        // w and the objective are unique even where lambda is not (rank < m).
        const VecX w = p.W * lambda + p.q;
        EXPECT_LT((w - p.w0).lpNorm<Eigen::Infinity>(), 1e-7);
        EXPECT_NEAR(CalcLcpObjective(p.W, p.q, lambda), CalcLcpObjective(p.W, p.q, p.lambda0),
                    1e-8);
        if (rank >= m) {
          EXPECT_LT((lambda - p.lambda0).lpNorm<Eigen::Infinity>(), 1e-6);
        }
      }
    }
  }
}

TEST(PgsSolverTest, ObjectiveDecreasesEverySweep) {
  // Unilateral and bounded bilateral rows; PD and singular W; plain GS and under-relaxation.
  std::mt19937 rng(9);
  std::normal_distribution<double> normal;
  for (int rank : {60, 15}) {
    const MatX W = MakeRandomPsd(30, rank, &rng);
    VecX q(30);
    std::vector<PgsRow> rows(30, MakeUnilateralRow());
    for (int c = 0; c < 30; ++c) {
      q[c] = normal(rng);
      if (c % 3 == 0) rows[c] = MakeBilateralRow(-0.5, 0.8);
    }
    for (double omega : {1.0, 0.7}) {
      PgsSettings one = ResidualSettings(0.0, 1);
      one.relaxation = omega;
      VecX lambda = VecX::Zero(30);
      double f = CalcLcpObjective(W, q, lambda);
      int decreases = 0;
      for (int s = 0; s < 300; ++s) {
        SolvePgs(W, q, rows, lambda, one);
        const double f_next = CalcLcpObjective(W, q, lambda);
        EXPECT_LE(f_next, f + 1e-13 * (1 + std::abs(f))) << "sweep " << s;
        decreases += f_next < f;
        f = f_next;
      }
      EXPECT_GT(decreases, 10);
      EXPECT_LT(CalcLcpResidual(W, q, rows, lambda).natural_map, 1e-4);
    }
  }
}

TEST(PgsSolverTest, RigidBoxOnGroundWithEightContactsConverges) {
  // Eight corner contacts of one rigid body (24 rows, rank 6): singular W with disk friction.
  std::vector<Vec3> corners;
  for (int k = 0; k < 8; ++k) {
    corners.push_back(Vec3(k & 1 ? 0.4 : -0.4, k & 2 ? 0.3 : -0.3, -0.2 - 0.01 * (k & 4)));
  }
  std::printf("  box on ground: v_t   sweeps to 1e-6 residual\n");
  for (double v_t : {0.05, 3.0}) {  // sticks, slides
    Eigen::Matrix<double, 6, 1> v_star;
    v_star << v_t, 0.5 * v_t, -1.0, 0.1, -0.2, 0.3;
    MatX W;
    VecX q;
    MakeRigidContacts(corners, v_star, &W, &q);
    std::vector<PgsRow> rows;
    for (int k = 0; k < 8; ++k) AppendContactRows(0.6, FrictionCone::kDisk, &rows);
    VecX lambda = VecX::Zero(24);
    const PgsStats stats = SolvePgs(W, q, rows, lambda, ResidualSettings(1e-6, 100000));
    std::printf("  %20.2f %8d\n", v_t, stats.sweeps);
    EXPECT_TRUE(stats.converged);
    EXPECT_TRUE(lambda.allFinite());
    double normal_sum = 0.0;
    for (int k = 0; k < 8; ++k) normal_sum += lambda[3 * k];
    EXPECT_GT(normal_sum, 0.5);  // about the mass times the normal speed 1
  }
}

TEST(PgsSolverTest, SolveAllocatesNothing) {
  // Every row kind, a skipped row, and the per-sweep residual.
  std::mt19937 rng(2);
  MatX W = MakeRandomPsd(14, 28, &rng);
  W.row(13).setZero();
  W.col(13).setZero();
  std::vector<PgsRow> rows;
  AppendContactRows(0.5, FrictionCone::kDisk, &rows);
  AppendContactRows(0.5, FrictionCone::kBox, &rows);
  rows.push_back(MakeUnilateralRow());
  rows.push_back(MakeBilateralRow());
  rows.push_back(MakeBilateralRow(-0.1, 0.2));
  rows.push_back(MakeUnilateralRow());
  PgsRow single = rows[1];
  single.partner = -1;
  rows.push_back(single);
  rows.push_back(MakeUnilateralRow());
  rows.push_back(MakeBilateralRow());
  rows.push_back(MakeUnilateralRow());
  VecX q = VecX::Constant(14, -0.3);
  VecX lambda = VecX::Zero(14);
  PgsSettings s = ResidualSettings(1e-12, 40);
  PgsStats stats;
  std::size_t allocations = 0;
  {
    AllocationCounter counter;
    stats = SolvePgs(W, q, rows, lambda, s);
    allocations = counter.count();
  }
  EXPECT_EQ(allocations, 0u);
  EXPECT_EQ(stats.skipped_rows, 1);
  EXPECT_EQ(stats.sweeps, 40);
  // The counter itself sees operator new and (where counted) Eigen's malloc.
  AllocationCounter probe;
  ::operator delete(::operator new(16));
  EXPECT_GE(probe.count(), 1u);
#if TAUT_TESTS_COUNT_MALLOC
  const std::size_t before = probe.count();
  VecX scratch(100);
  scratch.setZero();
  EXPECT_GT(probe.count(), before);
#endif
}

TEST(PgsSolverTest, BadSettingsThrow) {
  const MatX W = MatX::Identity(1, 1);
  VecX lambda = VecX::Zero(1);
  const std::vector<PgsRow> rows = {MakeUnilateralRow()};
  PgsSettings s;
  s.relaxation = 2.0;
  EXPECT_THROW(SolvePgs(W, VecX::Zero(1), rows, lambda, s), InputError);
  s = PgsSettings{};
  s.max_sweeps = -1;
  EXPECT_THROW(SolvePgs(W, VecX::Zero(1), rows, lambda, s), InputError);
  EXPECT_THROW(SolvePgs(W, VecX::Zero(2), rows, lambda, PgsSettings{}), InputError);
}

}  // namespace
}  // namespace taut
