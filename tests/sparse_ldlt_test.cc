#include "plugin/sparse_ldlt.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <random>
#include <vector>

#include "plugin/box_tet_mesher.h"
#include "tests/allocation_counter.h"
#include "tests/tet_block_spd.h"

namespace taut {
namespace {

using SparseMatrix = SparseLdlt::SparseMatrix;
using Triplet = Eigen::Triplet<double>;

// 7-point Laplacian of an nx x ny x nz grid plus shift * I (full symmetric CSC, SPD for shift > 0).
SparseMatrix MakeGridLaplacian(int nx, int ny, int nz, double shift) {
  const int n = nx * ny * nz;
  auto id = [&](int i, int j, int k) { return i + nx * (j + ny * k); };
  std::vector<Triplet> t;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const int a = id(i, j, k);
        t.emplace_back(a, a, 6.0 + shift);
        if (i + 1 < nx)
          t.emplace_back(a, id(i + 1, j, k), -1.0), t.emplace_back(id(i + 1, j, k), a, -1.0);
        if (j + 1 < ny)
          t.emplace_back(a, id(i, j + 1, k), -1.0), t.emplace_back(id(i, j + 1, k), a, -1.0);
        if (k + 1 < nz)
          t.emplace_back(a, id(i, j, k + 1), -1.0), t.emplace_back(id(i, j, k + 1), a, -1.0);
      }
  SparseMatrix A(n, n);
  A.setFromTriplets(t.begin(), t.end());
  return A;
}

// Random vector with entries in [-1, 1].
// The nonzero entries of B's columns as sparse columns.
SparseColumns ToSparseColumns(const MatX& B) {
  SparseColumns columns;
  for (Eigen::Index c = 0; c < B.cols(); ++c) {
    for (Eigen::Index i = 0; i < B.rows(); ++i)
      if (B(i, c) != 0.0) columns.Add(static_cast<int>(i), B(i, c));
    columns.EndColumn();
  }
  return columns;
}

VecX MakeRandomVec(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  return VecX::NullaryExpr(n, [&] { return u(rng); });
}

// ||x - y|| / ||y||.
double CalcRelError(const VecX& x, const VecX& y) { return (x - y).norm() / y.norm(); }

// Factors A with SparseLdlt and checks one solve against a dense LDLT solve; above 500 unknowns
// (dense LDLT is unblocked and takes seconds under sanitizers) against Eigen's SimplicialLDLT
// instead, plus a backward-error bound ||A x - b|| <= 1e-13 ||A||_F ||x||.
void ExpectSolveMatchesReference(const SparseMatrix& A, unsigned seed) {
  SparseLdlt ldlt;
  ldlt.Analyze(A);
  ASSERT_TRUE(ldlt.Factorize(A));
  EXPECT_EQ(ldlt.num_negative_pivots(), 0);
  const VecX b = MakeRandomVec(static_cast<int>(A.rows()), seed);
  VecX x = b;
  ldlt.Solve(x);
  VecX x_ref;
  if (A.rows() <= 500) {
    x_ref = Eigen::LDLT<MatX>(MatX(A)).solve(b);
  } else {
    x_ref = Eigen::SimplicialLDLT<SparseMatrix>(A).solve(b);
    EXPECT_LT((A * x - b).norm(), 1e-13 * A.norm() * x.norm());
  }
  EXPECT_LT(CalcRelError(x, x_ref), 1e-10) << "n = " << A.rows();
}

TEST(SparseLdltTest, SolvesGridLaplacianLikeReference) {
  ExpectSolveMatchesReference(MakeGridLaplacian(5, 4, 3, 0.1), 1);
  ExpectSolveMatchesReference(MakeGridLaplacian(8, 7, 8, 0.01), 1);     // 448 unknowns
  ExpectSolveMatchesReference(MakeGridLaplacian(14, 14, 15, 0.01), 2);  // 2940 unknowns
}

TEST(SparseLdltTest, SolvesTetBlockPatternLikeReference) {
  ExpectSolveMatchesReference(testing::MakeRandomTetBlockSpd(1, 1, 1, 3), 4);  // 24 unknowns
  ExpectSolveMatchesReference(testing::MakeRandomTetBlockSpd(3, 2, 2, 5), 6);  // 108 unknowns
  ExpectSolveMatchesReference(testing::MakeRandomTetBlockSpd(4, 4, 4, 5), 6);  // 375 unknowns
  ExpectSolveMatchesReference(testing::MakeRandomTetBlockSpd(9, 9, 9, 7), 8);  // 3000 unknowns
}

TEST(SparseLdltTest, SolvesSizeOneAndThree) {
  SparseMatrix A1(1, 1);
  A1.insert(0, 0) = 4.0;
  A1.makeCompressed();
  SparseLdlt ldlt;
  ldlt.Analyze(A1);
  ASSERT_TRUE(ldlt.Factorize(A1));
  VecX b = VecX::Constant(1, 2.0);
  ldlt.Solve(b);
  EXPECT_DOUBLE_EQ(b[0], 0.5);
  EXPECT_EQ(ldlt.nonzeros_in_L(), 0);

  Mat3 A3_dense;
  A3_dense << 4, 1, 0.5, 1, 3, -1, 0.5, -1, 5;
  const SparseMatrix A3 = A3_dense.sparseView();
  ExpectSolveMatchesReference(A3, 9);
}

TEST(SparseLdltTest, UpperTriangleInputEqualsFullInput) {
  const SparseMatrix A = testing::MakeRandomTetBlockSpd(2, 2, 1, 10);
  const SparseMatrix U = A.triangularView<Eigen::Upper>();
  SparseLdlt full, upper;
  full.Analyze(A);
  upper.Analyze(U);
  ASSERT_TRUE(full.Factorize(A));
  ASSERT_TRUE(upper.Factorize(U));
  EXPECT_EQ(full.permutation(), upper.permutation());
  EXPECT_EQ(full.nonzeros_in_L(), upper.nonzeros_in_L());
  VecX x_full = MakeRandomVec(static_cast<int>(A.rows()), 11), x_upper = x_full;
  full.Solve(x_full);
  upper.Solve(x_upper);
  EXPECT_EQ(x_full, x_upper);
}

TEST(SparseLdltTest, OrderingAndFillMatchEigenSimplicialLdlt) {
  const SparseMatrix A = testing::MakeRandomTetBlockSpd(4, 3, 3, 12);
  SparseLdlt ldlt;
  ldlt.Analyze(A);
  Eigen::SimplicialLDLT<SparseMatrix> eigen_ldlt(A);
  ASSERT_EQ(eigen_ldlt.info(), Eigen::Success);
  // Both use AMD on the same pattern, so L has the same nonzero count.
  EXPECT_EQ(ldlt.nonzeros_in_L(), eigen_ldlt.matrixL().nestedExpression().nonZeros());
  std::vector<int> sorted = ldlt.permutation();
  std::sort(sorted.begin(), sorted.end());
  for (int i = 0; i < ldlt.rows(); ++i) EXPECT_EQ(sorted[i], i);
  // AMD beats the natural ordering on a mesh pattern.
  Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower, Eigen::NaturalOrdering<int>> natural(A);
  EXPECT_LT(ldlt.nonzeros_in_L(), natural.matrixL().nestedExpression().nonZeros());
}

TEST(SparseLdltTest, RefactorizesWithNewValuesOnSamePattern) {
  SparseMatrix A = testing::MakeRandomTetBlockSpd(3, 3, 2, 13);
  SparseLdlt ldlt;
  ldlt.Analyze(A);
  ASSERT_TRUE(ldlt.Factorize(A));
  const VecX b = MakeRandomVec(static_cast<int>(A.rows()), 14);
  VecX x_old = b;
  ldlt.Solve(x_old);
  // New values, same pattern: written through the value array, as the body does.
  const SparseMatrix A_new = testing::MakeRandomTetBlockSpd(3, 3, 2, 15);
  ASSERT_EQ(A_new.nonZeros(), A.nonZeros());
  std::copy(A_new.valuePtr(), A_new.valuePtr() + A_new.nonZeros(), A.valuePtr());
  ASSERT_TRUE(ldlt.Factorize(A));
  VecX x_new = b;
  ldlt.Solve(x_new);
  const VecX x_ref = Eigen::LDLT<MatX>(MatX(A_new)).solve(b);
  EXPECT_LT(CalcRelError(x_new, x_ref), 1e-10);
  EXPECT_GT(CalcRelError(x_old, x_ref), 1e-3);  // the old factor would have been wrong
}

TEST(SparseLdltTest, SolveColumnsEqualsColumnByColumnSolve) {
  const SparseMatrix A = testing::MakeRandomTetBlockSpd(3, 3, 3, 16);
  const int n = static_cast<int>(A.rows());
  SparseLdlt ldlt;
  ldlt.Analyze(A);
  ASSERT_TRUE(ldlt.Factorize(A));
  // 37 = 2 x 16 + 4 + 1 columns exercises every block width; the columns sit inside a wider
  // matrix so the outer stride differs from the row count.
  MatX big(n + 5, 41);
  for (int c = 0; c < big.cols(); ++c) big.col(c) = MakeRandomVec(n + 5, 100 + c);
  // Sparse columns, as J^T has: the first lane of a 16-wide block, and all of the 4-wide and
  // 1-wide blocks (whose forward pass then skips zero rows).
  for (int c : {1, 33, 34, 35, 36, 37}) {
    big.col(c).setZero();
    big.col(c).segment(2 + (7 * c) % (n - 3), 3).setConstant(1.0);
  }
  MatX X = big;
  ldlt.SolveColumns(X.block(2, 1, n, 37));
  const MatX A_dense(A);
  for (int c = 1; c < 38; ++c) {
    VecX x = big.col(c).segment(2, n);
    ldlt.Solve(x);
    EXPECT_LT(CalcRelError(X.col(c).segment(2, n), x), 1e-14) << "column " << c;
    EXPECT_LT((A_dense * x - big.col(c).segment(2, n)).norm(), 1e-10 * big.col(c).norm());
  }
  // Untouched outside the block.
  EXPECT_EQ(X.col(0), big.col(0));
  EXPECT_EQ(X.col(40), big.col(40));
  EXPECT_EQ(X.topRows(2), big.topRows(2));
  EXPECT_EQ(X.bottomRows(3), big.bottomRows(3));
}

// B^T A^-1 B = Z^T Z for Z = HalfSolveColumns(B), and CompleteHalfSolve(Z c) = A^-1 B c, for
// both kernels, sparse columns (as J^T has, one with a repeated index whose entries are summed)
// and dense ones, every block width.
TEST(SparseLdltTest, HalfSolvesComposeToTheInverse) {
  const SparseMatrix A = testing::MakeRandomTetBlockSpd(3, 3, 3, 17);
  const int n = static_cast<int>(A.rows());
  const MatX A_inv = Eigen::LDLT<MatX>(MatX(A)).solve(MatX::Identity(n, n));
  MatX B(n, 23);  // 16 + 4 + 3 columns
  for (int c = 0; c < B.cols(); ++c) B.col(c) = MakeRandomVec(n, 300 + c);
  for (int c : {0, 5, 16, 17, 20, 22}) {
    B.col(c).setZero();
    B.col(c).segment((11 * c) % (n - 3), 3).setConstant(1.0);
  }
  SparseColumns columns = ToSparseColumns(B);
  // Column 22 again with its first entry split in two: the same column.
  columns.start.pop_back();
  columns.index.resize(columns.start.back());
  columns.value.resize(columns.start.back());
  const int split_row = (11 * 22) % (n - 3);
  columns.Add(split_row, -0.25);
  columns.Add(split_row, 1.25);
  columns.Add(split_row + 1, 1.0);
  columns.Add(split_row + 2, 1.0);
  columns.EndColumn();
  const MatX reference = B.transpose() * A_inv * B;
  const VecX c_weights = MakeRandomVec(static_cast<int>(B.cols()), 7);
  const VecX impulse = A_inv * (B * c_weights);
  for (SparseLdlt::Kernel kernel :
       {SparseLdlt::Kernel::kUpLooking, SparseLdlt::Kernel::kSupernodal}) {
    SparseLdlt ldlt;
    ldlt.Analyze(A, kernel);
    ASSERT_TRUE(ldlt.Factorize(A));
    for (int width : {1, 3, 4, 8, 23}) {
      SparseColumns first = columns;
      first.start.resize(width + 1);
      first.index.resize(first.start.back());
      first.value.resize(first.start.back());
      MatX Z(n, width);
      ldlt.HalfSolveColumns(first, Z);
      const MatX ref = reference.topLeftCorner(width, width);
      EXPECT_LT((Z.transpose() * Z - ref).norm(), 1e-12 * ref.norm())
          << "supernodal " << ldlt.supernodal() << " width " << width;
    }
    MatX Z(n, B.cols());
    ldlt.HalfSolveColumns(columns, Z);
    VecX v = Z * c_weights;
    ldlt.CompleteHalfSolve(v);
    EXPECT_LT(CalcRelError(v, impulse), 1e-12) << "supernodal " << ldlt.supernodal();
  }
}

TEST(SparseLdltTest, HalfSolveRejectsAnIndefiniteMatrix) {
  SparseMatrix A = testing::MakeRandomTetBlockSpd(2, 2, 2, 21);
  A.coeffRef(0, 0) -= 1e3;
  SparseLdlt ldlt;
  ldlt.Analyze(A, SparseLdlt::Kernel::kUpLooking);
  ASSERT_TRUE(ldlt.Factorize(A));
  ASSERT_GT(ldlt.num_negative_pivots(), 0);
  const SparseColumns B = ToSparseColumns(MatX::Identity(A.rows(), 2));
  MatX Z(A.rows(), 2);
  EXPECT_THROW(ldlt.HalfSolveColumns(B, Z), InputError);
}

TEST(SparseLdltTest, CountsNegativePivotsOfIndefiniteMatrix) {
  // Random symmetric pattern with a diagonal of mixed sign: negative pivots = negative eigenvalues.
  for (unsigned seed = 20; seed < 25; ++seed) {
    SparseMatrix A = testing::MakeRandomTetBlockSpd(2, 2, 2, seed);
    const int n = static_cast<int>(A.rows());
    std::mt19937 rng(seed);
    for (int i = 0; i < n; ++i)
      if (rng() % 3 == 0) A.coeffRef(i, i) -= 12.0;
    const Eigen::SelfAdjointEigenSolver<MatX> eig{MatX(A)};
    const int num_negative = static_cast<int>((eig.eigenvalues().array() < 0.0).count());
    ASSERT_GT(num_negative, 0);
    SparseLdlt ldlt;
    ldlt.Analyze(A);
    ASSERT_TRUE(ldlt.Factorize(A));
    EXPECT_EQ(ldlt.num_negative_pivots(), num_negative) << "seed " << seed;
    const VecX b = MakeRandomVec(n, seed);
    VecX x = b;
    ldlt.Solve(x);
    EXPECT_LT((MatX(A) * x - b).norm(), 1e-8 * b.norm() * eig.eigenvalues().cwiseAbs().maxCoeff());
  }
}

TEST(SparseLdltTest, ReportsZeroAndNonFinitePivots) {
  SparseMatrix A = MakeGridLaplacian(4, 3, 3, 0.5);
  const int dead = 17;
  // Zero row and column `dead` (kept in the pattern): its pivot is exactly zero.
  for (int c = 0; c < A.cols(); ++c)
    for (SparseMatrix::InnerIterator it(A, c); it; ++it)
      if (it.row() == dead || it.col() == dead) it.valueRef() = 0.0;
  SparseLdlt ldlt;
  ldlt.Analyze(A);
  EXPECT_FALSE(ldlt.Factorize(A));
  EXPECT_EQ(ldlt.failed_column(), dead);
  EXPECT_FALSE(ldlt.factorized());
  VecX b = VecX::Ones(A.rows());
  EXPECT_THROW(ldlt.Solve(b), InputError);

  // A NaN entry is caught; restoring the values recovers.
  A = MakeGridLaplacian(4, 3, 3, 0.5);
  A.coeffRef(5, 5) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(ldlt.Factorize(A));
  EXPECT_NE(ldlt.failed_column(), -1);
  A.coeffRef(5, 5) = 6.5;
  EXPECT_TRUE(ldlt.Factorize(A));
  EXPECT_EQ(ldlt.failed_column(), -1);
  EXPECT_TRUE(ldlt.factorized());
}

TEST(SparseLdltTest, RejectsBadInput) {
  SparseLdlt ldlt;
  const SparseMatrix A = MakeGridLaplacian(3, 3, 2, 1.0);
  EXPECT_THROW(ldlt.Factorize(A), InputError);  // before Analyze
  EXPECT_THROW(ldlt.Analyze(SparseMatrix(3, 4)), InputError);
  EXPECT_THROW(ldlt.Analyze(SparseMatrix(0, 0)), InputError);
  SparseMatrix uncompressed = A;
  uncompressed.uncompress();
  EXPECT_THROW(ldlt.Analyze(uncompressed), InputError);
  ldlt.Analyze(A);
  EXPECT_THROW(ldlt.Factorize(MakeGridLaplacian(3, 3, 3, 1.0)), InputError);  // other size
  SparseMatrix other_pattern = A;
  other_pattern.coeffRef(0, 17) = 1.0;
  other_pattern.makeCompressed();
  EXPECT_THROW(ldlt.Factorize(other_pattern), InputError);  // extra nonzero
  VecX b = VecX::Ones(A.rows());
  EXPECT_THROW(ldlt.Solve(b), InputError);  // before Factorize
  ASSERT_TRUE(ldlt.Factorize(A));
  VecX wrong = VecX::Ones(A.rows() + 1);
  EXPECT_THROW(ldlt.Solve(wrong), InputError);
  MatX wrong_B = MatX::Ones(A.rows() - 1, 3);
  EXPECT_THROW(ldlt.SolveColumns(wrong_B), InputError);
}

TEST(SparseLdltTest, FactorizeAndSolveDoNotAllocate) {
  SparseMatrix A = testing::MakeRandomTetBlockSpd(4, 4, 3, 30);
  const int n = static_cast<int>(A.rows());
  SparseLdlt ldlt;
  ldlt.Analyze(A);
  VecX b = MakeRandomVec(n, 31);
  MatX B = MatX::Random(n, 45);
  // The counter sees a std::vector allocation, so a zero below is not vacuous.
  {
    testing::ScopedAllocationCounter probe;
    std::vector<double> v(n);
    ASSERT_GT(probe.count(), 0u);
  }
#if TAUT_TESTS_COUNT_MALLOC
  {  // With malloc counted, Eigen's SimplicialLDLT::factorize shows why this class exists.
    Eigen::SimplicialLDLT<SparseMatrix> eigen_ldlt;
    eigen_ldlt.analyzePattern(A);
    testing::ScopedAllocationCounter eigen_counter;
    eigen_ldlt.factorize(A);
    EXPECT_GT(eigen_counter.count(), 0u);
  }
#endif
  // Zero from the first Factorize on: Analyze sized every buffer. (allocation_counter.cc counts
  // operator new, and malloc too on glibc without sanitizers, which catches Eigen's storage.)
  testing::ScopedAllocationCounter counter;
  bool ok = true;
  for (int step = 0; step < 3; ++step) {
    A.valuePtr()[0] += 0.25;  // new values on the same pattern
    ok = ok && ldlt.Factorize(A);
    ldlt.Solve(b);
    ldlt.SolveColumns(B);
    ldlt.SolveColumns(B.middleCols(3, 20));
  }
  const std::size_t num_allocations = counter.count();
  EXPECT_TRUE(ok);
  EXPECT_EQ(num_allocations, 0u);
}

}  // namespace
}  // namespace taut
