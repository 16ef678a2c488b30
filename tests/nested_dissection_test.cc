#include "plugin/nested_dissection.h"

#include <gtest/gtest.h>

#include <Eigen/SparseCholesky>
#include <algorithm>
#include <random>
#include <vector>

#include "plugin/sparse_ldlt.h"
#include "tests/tet_block_spd.h"

namespace taut {
namespace {

using SparseMatrix = SparseLdlt::SparseMatrix;

// True when `perm` holds every index 0..n-1 once.
bool IsPermutation(std::vector<int> perm, int n) {
  if (static_cast<int>(perm.size()) != n) return false;
  std::sort(perm.begin(), perm.end());
  for (int i = 0; i < n; ++i)
    if (perm[i] != i) return false;
  return true;
}

TEST(NestedDissectionTest, OrdersNodeBlocksAsWholes) {
  const SparseMatrix A = testing::MakeRandomTetBlockSpd(4, 3, 3, 1);
  const int n = static_cast<int>(A.rows());
  const std::vector<int> perm = CalcNestedDissectionOrdering(A, /*blocks_of_three=*/true);
  ASSERT_TRUE(IsPermutation(perm, n));
  // Each node's three DOFs are eliminated one after the other, x, y, z.
  for (int k = 0; k < n; k += 3) {
    EXPECT_EQ(perm[k] % 3, 0) << "position " << k;
    EXPECT_EQ(perm[k + 1], perm[k] + 1);
    EXPECT_EQ(perm[k + 2], perm[k] + 2);
  }
}

TEST(NestedDissectionTest, OrdersScalarGraphsToo) {
  // 7 unknowns (not a multiple of 3): the scalar graph of a path 0 - 1 - ... - 6.
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < 7; ++i) {
    t.emplace_back(i, i, 4.0);
    if (i + 1 < 7) t.emplace_back(i, i + 1, -1.0), t.emplace_back(i + 1, i, -1.0);
  }
  SparseMatrix A(7, 7);
  A.setFromTriplets(t.begin(), t.end());
  EXPECT_TRUE(IsPermutation(CalcNestedDissectionOrdering(A, true), 7));
  EXPECT_TRUE(IsPermutation(CalcNestedDissectionOrdering(A, false), 7));
}

TEST(NestedDissectionTest, RejectsNonSquareMatrix) {
  SparseMatrix A(3, 4);
  A.makeCompressed();
  EXPECT_THROW(CalcNestedDissectionOrdering(A, true), InputError);
}

// A cube of tets: nested dissection fills L less than AMD there (a 3D mesh whose separators are
// planes), so SparseLdlt's automatic choice takes it, and the factor solves the same system.
TEST(NestedDissectionTest, SparseLdltTakesNestedDissectionWhereItFillsLess) {
  const SparseMatrix A = testing::MakeRandomTetBlockSpd(10, 10, 10, 2);
  SparseLdlt amd, nd, chosen;
  amd.Analyze(A, SparseLdlt::Kernel::kAuto, SparseLdlt::Ordering::kAmd);
  nd.Analyze(A, SparseLdlt::Kernel::kAuto, SparseLdlt::Ordering::kNestedDissection);
  chosen.Analyze(A);
  EXPECT_EQ(amd.ordering(), SparseLdlt::Ordering::kAmd);
  EXPECT_EQ(nd.ordering(), SparseLdlt::Ordering::kNestedDissection);
  EXPECT_TRUE(IsPermutation(nd.permutation(), static_cast<int>(A.rows())));
  ASSERT_GE(amd.CalcFactorWork(), SparseLdlt::kNestedDissectionMinWork);
  EXPECT_LT(nd.nonzeros_in_L(), amd.nonzeros_in_L());
  EXPECT_LE(nd.CalcFactorWork(), SparseLdlt::kNestedDissectionWorkRatio * amd.CalcFactorWork());
  EXPECT_EQ(chosen.ordering(), SparseLdlt::Ordering::kNestedDissection);
  EXPECT_EQ(chosen.permutation(), nd.permutation());

  ASSERT_TRUE(amd.Factorize(A));
  ASSERT_TRUE(chosen.Factorize(A));
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const VecX b = VecX::NullaryExpr(A.rows(), [&] { return u(rng); });
  VecX x_amd = b, x_nd = b;
  amd.Solve(x_amd);
  chosen.Solve(x_nd);
  EXPECT_LT((x_nd - x_amd).norm(), 1e-10 * x_amd.norm());
  EXPECT_LT((A * x_nd - b).norm(), 1e-12 * b.norm() * A.norm());
}

// Small bodies keep AMD: below kNestedDissectionMinWork nested dissection is not even tried.
TEST(NestedDissectionTest, SparseLdltKeepsAmdForSmallBodies) {
  const SparseMatrix A = testing::MakeRandomTetBlockSpd(4, 3, 3, 4);
  SparseLdlt ldlt;
  ldlt.Analyze(A);
  EXPECT_LT(ldlt.CalcFactorWork(), SparseLdlt::kNestedDissectionMinWork);
  EXPECT_EQ(ldlt.ordering(), SparseLdlt::Ordering::kAmd);
}

}  // namespace
}  // namespace taut
