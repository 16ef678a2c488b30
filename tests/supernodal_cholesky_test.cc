// SparseLdlt's supernodal kernel (plugin/supernodal_cholesky.h) against its up-looking kernel on
// the same ordering: the same solutions, pivots and fill, and failure on matrices that are not
// SPD.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "bullet_bridge/island_thread_pool.h"
#include "plugin/box_tet_mesher.h"
#include "plugin/sparse_ldlt.h"
#include "tests/tet_block_spd.h"

namespace taut {
namespace {

using SnSparse = SparseLdlt::SparseMatrix;

MatX MakeSnRhs(int n, int cols, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  return MatX::NullaryExpr(n, cols, [&] { return u(rng); });
}

// Factors A with both kernels and compares fill, pivots and a block of solves.
void ExpectKernelsAgree(const SnSparse& A, int num_rhs) {
  SparseLdlt up, sn;
  up.Analyze(A, SparseLdlt::Kernel::kUpLooking);
  sn.Analyze(A, SparseLdlt::Kernel::kSupernodal);
  ASSERT_FALSE(up.supernodal());
  ASSERT_TRUE(sn.supernodal());
  EXPECT_EQ(up.nonzeros_in_L(), sn.nonzeros_in_L());
  ASSERT_TRUE(up.Factorize(A));
  ASSERT_TRUE(sn.Factorize(A));
  EXPECT_EQ(sn.num_negative_pivots(), 0);
  for (int k = 0; k < A.rows(); ++k)
    EXPECT_NEAR(sn.pivots()[k], up.pivots()[k], 1e-10 * up.pivots()[k]) << "pivot " << k;
  const MatX B = MakeSnRhs(static_cast<int>(A.rows()), num_rhs, 7);
  MatX X_up = B, X_sn = B;
  up.SolveColumns(X_up);
  sn.SolveColumns(X_sn);
  EXPECT_LT((X_sn - X_up).norm(), 1e-10 * X_up.norm()) << "n = " << A.rows();
  EXPECT_LT((A * X_sn - B).norm(), 1e-12 * A.norm() * X_sn.norm());
  VecX x = B.col(0);
  sn.Solve(x);
  EXPECT_LT((x - X_sn.col(0)).norm(), 1e-14 * x.norm());
}

TEST(SupernodalCholeskyTest, SolvesLikeTheUpLookingKernel) {
  ExpectKernelsAgree(testing::MakeRandomTetBlockSpd(2, 1, 1, 1), 1);  // a few supernodes
  ExpectKernelsAgree(testing::MakeRandomTetBlockSpd(8, 3, 3, 2), 5);  // 432 unknowns
  ExpectKernelsAgree(testing::MakeRandomTetBlockSpd(14, 4, 4, 3),
                     37);  // 16 + 16 + 5 columns per pass
}

TEST(SupernodalCholeskyTest, AutoKernelFollowsTheFactorWork) {
  const SnSparse small = testing::MakeRandomTetBlockSpd(3, 2, 2, 4);
  const SnSparse large = testing::MakeRandomTetBlockSpd(20, 5, 5, 5);
  SparseLdlt a, b;
  a.Analyze(small);
  b.Analyze(large);
  EXPECT_LT(a.CalcFactorWork(), SparseLdlt::kSupernodalMinWork);
  EXPECT_FALSE(a.supernodal());
  EXPECT_GE(b.CalcFactorWork(), SparseLdlt::kSupernodalMinWork);
  EXPECT_TRUE(b.supernodal());
}

TEST(SupernodalCholeskyTest, RefactorsNewValuesOnTheSamePattern) {
  SnSparse A = testing::MakeRandomTetBlockSpd(6, 3, 2, 6);
  SparseLdlt sn;
  sn.Analyze(A, SparseLdlt::Kernel::kSupernodal);
  ASSERT_TRUE(sn.Factorize(A));
  for (int k = 0; k < A.outerSize(); ++k)
    for (SnSparse::InnerIterator it(A, k); it; ++it)
      if (it.row() == it.col()) it.valueRef() *= 3.0;  // still SPD, a different factor
  ASSERT_TRUE(sn.Factorize(A));
  const VecX b = MakeSnRhs(static_cast<int>(A.rows()), 1, 8);
  VecX x = b;
  sn.Solve(x);
  EXPECT_LT((A * x - b).norm(), 1e-12 * b.norm());
}

TEST(SupernodalCholeskyTest, FailsOnAMatrixThatIsNotPositiveDefinite) {
  SnSparse A = testing::MakeRandomTetBlockSpd(6, 3, 2, 9);
  const SnSparse A_spd = A;
  // Shifting by -1.0 I takes the diagonal mass below zero on some DOFs: A is indefinite.
  for (int k = 0; k < A.outerSize(); ++k)
    for (SnSparse::InnerIterator it(A, k); it; ++it)
      if (it.row() == it.col()) it.valueRef() -= 1.0e3;
  SparseLdlt sn;
  sn.Analyze(A, SparseLdlt::Kernel::kSupernodal);
  EXPECT_FALSE(sn.Factorize(A));
  EXPECT_FALSE(sn.factorized());
  EXPECT_GE(sn.failed_column(), 0);
  EXPECT_LT(sn.failed_column(), A.rows());
  EXPECT_EQ(sn.num_negative_pivots(), 1);
  // A non-finite entry fails too; the object then factors an SPD matrix again.
  SnSparse A_nan = A_spd;
  A_nan.valuePtr()[0] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(sn.Factorize(A_nan));
  EXPECT_TRUE(sn.Factorize(A_spd));
  EXPECT_TRUE(sn.factorized());
}

// The preconditioner solve through fl32(L): a symmetric operator (forward and backward halves
// use the same rounded L), within single-precision rounding of A^-1 but not equal to it, and
// Solve again once a new Factorize makes the copy stale.
TEST(SupernodalCholeskyTest, SinglePrecisionSolveInvertsTheRoundedFactor) {
  SnSparse A = testing::MakeRandomTetBlockSpd(10, 4, 3, 11);
  SparseLdlt sn;
  sn.Analyze(A, SparseLdlt::Kernel::kSupernodal);
  ASSERT_TRUE(sn.Factorize(A));
  const MatX B = MakeSnRhs(static_cast<int>(A.rows()), 2, 12);
  VecX x_double = B.col(0), x_single = B.col(0);
  sn.Solve(x_double);
  sn.SolveSinglePrecision(x_single);  // no copy yet: the double solve
  EXPECT_EQ(x_single, x_double);
  sn.MakeSinglePrecisionCopy();
  x_single = B.col(0);
  sn.SolveSinglePrecision(x_single);
  const double difference = (x_single - x_double).norm() / x_double.norm();
  EXPECT_GT(difference, 1e-12);  // the rounded factor was used
  EXPECT_LT(difference, 1e-5);
  // u^T P^-1 v = v^T P^-1 u for P = L_f L_f^T.
  VecX p_u = B.col(0), p_v = B.col(1);
  sn.SolveSinglePrecision(p_u);
  sn.SolveSinglePrecision(p_v);
  EXPECT_NEAR(B.col(1).dot(p_u), B.col(0).dot(p_v), 1e-12 * p_u.norm() * B.col(1).norm());
  // P^-1 is positive definite.
  EXPECT_GT(B.col(0).dot(p_u), 0.0);
  // A new factorization leaves the copy stale: the double solve of the new A again.
  ASSERT_TRUE(sn.Factorize(A));
  VecX x_after = B.col(0);
  sn.SolveSinglePrecision(x_after);
  EXPECT_EQ(x_after, x_double);
}

// Two threads factor the two groups of subtrees below the first branching, then the supernodes
// above: the same pivots and solves bit for bit as one thread, and the same failed column.
TEST(SupernodalCholeskyTest, TwoThreadsFactorBitwiseLikeOne) {
  const SnSparse A = testing::MakeRandomTetBlockSpd(14, 10, 8, 21);
  SparseLdlt one, two;
  one.Analyze(A, SparseLdlt::Kernel::kSupernodal);
  two.Analyze(A, SparseLdlt::Kernel::kSupernodal);
  IslandThreadPool pool(2);
  ASSERT_TRUE(one.Factorize(A));
  ASSERT_TRUE(two.Factorize(A, &pool));
  EXPECT_EQ(one.pivots(), two.pivots());
  const MatX B = MakeSnRhs(static_cast<int>(A.rows()), 3, 22);
  MatX X_one = B, X_two = B;
  one.SolveColumns(X_one);
  two.SolveColumns(X_two);
  EXPECT_EQ(X_one, X_two);
  EXPECT_LT((A * X_two - B).norm(), 1e-12 * A.norm() * X_two.norm());
  // An indefinite A fails at the same column on both.
  SnSparse indefinite = A;
  for (int k = 0; k < indefinite.outerSize(); ++k)
    for (SnSparse::InnerIterator it(indefinite, k); it; ++it)
      if (it.row() == it.col()) it.valueRef() -= 1.0e3;
  EXPECT_FALSE(one.Factorize(indefinite));
  EXPECT_FALSE(two.Factorize(indefinite, &pool));
  EXPECT_EQ(one.failed_column(), two.failed_column());
  EXPECT_EQ(one.num_negative_pivots(), two.num_negative_pivots());
}

// The split itself: both groups carry at least kMinGroupShare of the work, and the factor of a
// matrix below kMinSplitWork is not split.
TEST(SupernodalCholeskyTest, TwoWaySplitBalancesTheSubtrees) {
  const SnSparse A = testing::MakeRandomTetBlockSpd(14, 10, 8, 21);
  SparseLdlt ldlt;
  ldlt.Analyze(A, SparseLdlt::Kernel::kSupernodal);
  const SupernodalCholesky& factor = ldlt.supernodal_factor();
  ASSERT_TRUE(factor.has_two_way_split());
  const std::array<double, 3>& work = factor.split_work();
  const double total = work[0] + work[1] + work[2];
  std::printf("split work: %.3g + %.3g on two threads, %.3g above (of %.3g)\n", work[0], work[1],
              work[2], total);
  EXPECT_GE(std::min(work[0], work[1]), SupernodalCholesky::kMinGroupShare * total);
  SparseLdlt small;
  small.Analyze(testing::MakeRandomTetBlockSpd(3, 2, 2, 4), SparseLdlt::Kernel::kSupernodal);
  EXPECT_FALSE(small.supernodal_factor().has_two_way_split());
}

}  // namespace
}  // namespace taut
