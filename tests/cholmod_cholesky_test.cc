#include "plugin/cholmod_cholesky.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <limits>
#include <memory>
#include <random>
#include <utility>
#include <vector>

#include "plugin/box_tet_mesher.h"
#include "plugin/hex_element_model.h"
#include "plugin/hex_shapes.h"
#include "plugin/implicit_system.h"
#include "plugin/tet_element_model.h"
#include "tests/allocation_counter.h"
#include "tests/tet_block_spd.h"

namespace taut {
namespace {

using SparseMatrix = CholmodCholesky::SparseMatrix;
using Triplet = Eigen::Triplet<double>;

// Random vector with entries in [-1, 1].
VecX MakeRandomVec(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  return VecX::NullaryExpr(n, [&] { return u(rng); });
}

// ||x - y|| / ||y||.
double CalcRelError(const VecX& x, const VecX& y) { return (x - y).norm() / y.norm(); }

// Analyzes and factors A, which must succeed.
void AnalyzeAndFactor(CholmodCholesky& chol, const SparseMatrix& A) {
  chol.Analyze(A);
  ASSERT_TRUE(chol.Factorize(A)) << "failed column " << chol.failed_column();
}

TEST(CholmodCholeskyTest, SolvesRandomSpdSystemsLikeEigenSimplicialLdlt) {
  // 24, 375 and 3000 unknowns: one supernode up to many.
  for (const auto& [cells, seed] : {std::pair{1, 3u}, std::pair{4, 5u}, std::pair{9, 7u}}) {
    const SparseMatrix A = testing::MakeRandomTetBlockSpd(cells, cells, cells, seed);
    CholmodCholesky chol;
    AnalyzeAndFactor(chol, A);
    EXPECT_TRUE(chol.factorized());
    EXPECT_GT(chol.num_supernodes(), 0);
    const VecX b = MakeRandomVec(static_cast<int>(A.rows()), seed + 1);
    VecX x = b;
    chol.Solve(x);
    const VecX x_ref = Eigen::SimplicialLDLT<SparseMatrix>(A).solve(b);
    EXPECT_LT(CalcRelError(x, x_ref), 1e-10) << "n = " << A.rows();
    EXPECT_LT((A * x - b).norm(), 1e-13 * A.norm() * x.norm()) << "n = " << A.rows();
  }
}

TEST(CholmodCholeskyTest, ReadsOnlyTheUpperTriangleAndPermutesAllColumns) {
  const SparseMatrix A = testing::MakeRandomTetBlockSpd(3, 2, 2, 10);
  SparseMatrix U = A.triangularView<Eigen::Upper>();
  CholmodCholesky full, upper;
  AnalyzeAndFactor(full, A);
  AnalyzeAndFactor(upper, U);
  VecX x_full = MakeRandomVec(static_cast<int>(A.rows()), 11), x_upper = x_full;
  full.Solve(x_full);
  upper.Solve(x_upper);
  EXPECT_LT(CalcRelError(x_upper, x_full), 1e-14);
  std::vector<int> sorted = full.permutation();
  std::sort(sorted.begin(), sorted.end());
  for (int i = 0; i < full.rows(); ++i) ASSERT_EQ(sorted[i], i);
}

TEST(CholmodCholeskyTest, SolveColumnsEqualsColumnByColumnSolve) {
  const SparseMatrix A = testing::MakeRandomTetBlockSpd(3, 3, 3, 16);
  const int n = static_cast<int>(A.rows());
  CholmodCholesky chol;
  AnalyzeAndFactor(chol, A);
  // Two full blocks and a partial one inside a wider matrix, so the outer stride differs from
  // the row count.
  const int m = 2 * CholmodCholesky::kMaxBlockColumns + 9;
  MatX big(n + 5, m + 4);
  for (int c = 0; c < big.cols(); ++c) big.col(c) = MakeRandomVec(n + 5, 100 + c);
  MatX X = big;
  chol.SolveColumns(X.block(2, 1, n, m));
  for (int c = 1; c <= m; ++c) {
    VecX x = big.col(c).segment(2, n);
    chol.Solve(x);
    EXPECT_LT(CalcRelError(X.col(c).segment(2, n), x), 1e-13) << "column " << c;
    EXPECT_LT((A * x - big.col(c).segment(2, n)).norm(), 1e-10 * big.col(c).norm());
  }
  EXPECT_EQ(X.col(0), big.col(0));
  EXPECT_EQ(X.rightCols(3), big.rightCols(3));
  EXPECT_EQ(X.topRows(2), big.topRows(2));
  EXPECT_EQ(X.bottomRows(3), big.bottomRows(3));
}

TEST(CholmodCholeskyTest, RefactorsNewValuesAndSurvivesAMove) {
  SparseMatrix A = testing::MakeRandomTetBlockSpd(3, 3, 2, 13);
  CholmodCholesky chol;
  AnalyzeAndFactor(chol, A);
  const VecX b = MakeRandomVec(static_cast<int>(A.rows()), 14);
  VecX x_old = b;
  chol.Solve(x_old);
  const SparseMatrix A_new = testing::MakeRandomTetBlockSpd(3, 3, 2, 15);
  std::copy(A_new.valuePtr(), A_new.valuePtr() + A_new.nonZeros(), A.valuePtr());
  CholmodCholesky moved = std::move(chol);
  ASSERT_TRUE(moved.Factorize(A));
  VecX x_new = b;
  moved.Solve(x_new);
  const VecX x_ref = Eigen::SimplicialLDLT<SparseMatrix>(A_new).solve(b);
  EXPECT_LT(CalcRelError(x_new, x_ref), 1e-10);
  EXPECT_GT(CalcRelError(x_old, x_ref), 1e-3);  // the old factor would have been wrong
}

TEST(CholmodCholeskyTest, ReportsIndefiniteAndNonFiniteMatricesAndRecovers) {
  SparseMatrix A = testing::MakeRandomTetBlockSpd(2, 2, 2, 20);
  const SparseMatrix A_good = A;
  const int dead = 17;
  A.coeffRef(dead, dead) = -50.0;  // a negative eigenvalue
  ASSERT_LT(Eigen::SelfAdjointEigenSolver<MatX>(MatX(A)).eigenvalues()[0], 0.0);
  CholmodCholesky chol;
  chol.Analyze(A);
  EXPECT_FALSE(chol.Factorize(A));
  EXPECT_GE(chol.failed_column(), 0);
  EXPECT_LT(chol.failed_column(), chol.rows());
  EXPECT_FALSE(chol.factorized());
  VecX b = VecX::Ones(A.rows());
  EXPECT_THROW(chol.Solve(b), InputError);

  // A NaN in the upper triangle names its column; good values on the same pattern recover.
  A = A_good;
  const int column = 9;
  const int row = A.innerIndexPtr()[A.outerIndexPtr()[column]];  // first stored row, <= column
  ASSERT_LT(row, column);
  A.coeffRef(row, column) = std::numeric_limits<double>::quiet_NaN();
  A.coeffRef(column, row) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(chol.Factorize(A));
  EXPECT_EQ(chol.failed_column(), column);
  ASSERT_TRUE(chol.Factorize(A_good));
  EXPECT_EQ(chol.failed_column(), -1);
  chol.Solve(b);
  EXPECT_LT((A_good * b - VecX::Ones(A.rows())).norm(), 1e-12 * A_good.norm() * b.norm());
}

TEST(CholmodCholeskyTest, RejectsBadInput) {
  CholmodCholesky chol;
  const SparseMatrix A = testing::MakeRandomTetBlockSpd(2, 1, 1, 1);
  EXPECT_THROW(chol.Factorize(A), InputError);  // before Analyze
  EXPECT_THROW(chol.Analyze(SparseMatrix(3, 4)), InputError);
  EXPECT_THROW(chol.Analyze(SparseMatrix(0, 0)), InputError);
  SparseMatrix uncompressed = A;
  uncompressed.uncompress();
  EXPECT_THROW(chol.Analyze(uncompressed), InputError);
  chol.Analyze(A);
  EXPECT_THROW(chol.Factorize(testing::MakeRandomTetBlockSpd(2, 2, 1, 1)),
               InputError);  // other size
  SparseMatrix other_pattern = A;
  other_pattern.coeffRef(0, A.cols() - 1) = 1.0;
  other_pattern.makeCompressed();
  EXPECT_THROW(chol.Factorize(other_pattern), InputError);  // extra nonzero
  VecX b = VecX::Ones(A.rows());
  EXPECT_THROW(chol.Solve(b), InputError);  // before Factorize
  ASSERT_TRUE(chol.Factorize(A));
  VecX wrong = VecX::Ones(A.rows() + 1);
  EXPECT_THROW(chol.Solve(wrong), InputError);
  MatX wrong_B = MatX::Ones(A.rows() - 1, 3);
  EXPECT_THROW(chol.SolveColumns(wrong_B), InputError);
}

TEST(CholmodCholeskyTest, SolvesDoNotAllocateButFactorizeDoes) {
  SparseMatrix A = testing::MakeRandomTetBlockSpd(4, 4, 3, 30);
  const int n = static_cast<int>(A.rows());
  CholmodCholesky chol;
  AnalyzeAndFactor(chol, A);
  VecX b = MakeRandomVec(n, 31);
  MatX B = MatX::Random(n, CholmodCholesky::kMaxBlockColumns + 13);
  chol.Solve(b);  // the first BLAS calls may set up the BLAS's own buffers
  chol.SolveColumns(B);
  testing::ScopedAllocationCounter counter;
  for (int i = 0; i < 3; ++i) {
    chol.Solve(b);
    chol.SolveColumns(B);
    chol.SolveColumns(B.middleCols(3, 20));
  }
  EXPECT_EQ(counter.count(), 0u);
#if TAUT_TESTS_COUNT_MALLOC
  // With malloc counted: CHOLMOD allocates inside every numeric factorization, which is why
  // ImplicitSystem keeps SparseLdlt for small bodies.
  testing::ScopedAllocationCounter factor_counter;
  ASSERT_TRUE(chol.Factorize(A));
  EXPECT_GT(factor_counter.count(), 0u);
#endif
}

// Steps of A v = M v0 + h f(x0), x += h v (DeformableBody::BeginStep without constraints: K
// co-rotated at each step's start, gravity) with the given backend; returns the final x.
VecX RunImplicitSteps(ElementModel& model, const std::vector<NodeKind>& kinds, double density,
                      LinearSolverKind kind, bool& used_cholmod) {
  const double h = 1.0 / 60.0;
  ImplicitSystem system;
  system.set_linear_solver(kind);
  system.Build(model, kinds);
  used_cholmod = system.uses_cholmod();
  VecX mass;
  model.CalcLumpedMass(density, mass);
  VecX x = model.rest_positions(), v = VecX::Zero(x.size()), f(x.size()), rhs(x.size());
  for (int step = 0; step < 4; ++step) {
    f.setZero();
    model.UpdateRotationsAndAddForces(x, f);
    for (int i = 0; i < model.num_nodes(); ++i) {
      f[3 * i + 2] -= 9.81 * mass[i];
      rhs.segment<3>(3 * i) = mass[i] * v.segment<3>(3 * i) + h * f.segment<3>(3 * i);
    }
    system.Assemble(model, mass, 1.0, h * h);
    system.Factor("test body");
    system.Solve(rhs);
    v = rhs;
    x += h * v;
  }
  return x;
}

// Displacement after the steps with SparseLdlt and with CHOLMOD must agree to round-off.
void ExpectSameSteps(ElementModel& model, const std::vector<NodeKind>& kinds, double density) {
  bool ldlt_used_cholmod = true, cholmod_used_cholmod = false;
  const VecX X = model.rest_positions();
  const VecX u_ldlt =
      RunImplicitSteps(model, kinds, density, LinearSolverKind::kSparseLdlt, ldlt_used_cholmod) - X;
  const VecX u_chol =
      RunImplicitSteps(model, kinds, density, LinearSolverKind::kCholmod, cholmod_used_cholmod) - X;
  EXPECT_FALSE(ldlt_used_cholmod);
  EXPECT_TRUE(cholmod_used_cholmod);
  EXPECT_GT(u_ldlt.norm(), 1e-3);  // the body moved (sagged or fell)
  EXPECT_LT(CalcRelError(u_chol, u_ldlt), 1e-10);
}

TEST(CholmodCholeskyTest, FemStepMatchesSparseLdltForTetBeamAndHexBall) {
  // Soft cantilever, x = 0 end fixed (1,215 free DOFs), sagging.
  TetElementModel beam(std::make_shared<TetMesh>(MakeBoxTetMesh(Vec3(1, 0.2, 0.2), 15, 3, 3)),
                       Material{2e4, 0.3, 1000.0});
  std::vector<NodeKind> kinds(beam.num_nodes(), NodeKind::kFree);
  for (int i = 0; i < beam.num_nodes(); ++i)
    if (beam.rest_positions()[3 * i] < 1e-9) kinds[i] = NodeKind::kFixed;
  ExpectSameSteps(beam, kinds, 1000.0);

  // Free-falling hex ball of armadillo resolution (~1,900 free DOFs).
  HexElementModel ball(std::make_shared<HexLattice>(MakeSphereHexLattice(1.0, 2.0 / 9)),
                       Material{5e5, 0.3, 500.0});
  ExpectSameSteps(ball, std::vector<NodeKind>(ball.num_nodes(), NodeKind::kFree), 500.0);
}

TEST(CholmodCholeskyTest, ImplicitSystemPicksCholmodFromTheThreshold) {
  // Free-DOF counts of a beam with its x = 0 face fixed: 3 (nx n_yz) with n_yz nodes per face.
  for (const auto& [nx, expect_cholmod] : {std::pair{3, false}, std::pair{60, true}}) {
    TetElementModel beam(std::make_shared<TetMesh>(MakeBoxTetMesh(Vec3(1, 0.2, 0.2), nx, 2, 2)),
                         Material{2e5, 0.3, 1000.0});
    std::vector<NodeKind> kinds(beam.num_nodes(), NodeKind::kFree);
    for (int i = 0; i < beam.num_nodes(); ++i)
      if (beam.rest_positions()[3 * i] < 1e-9) kinds[i] = NodeKind::kFixed;
    ImplicitSystem system;
    system.Build(beam, kinds);
    EXPECT_EQ(system.num_free_dofs(), 3 * nx * 9);
    EXPECT_EQ(system.num_free_dofs() >= ImplicitSystem::kCholmodMinFreeDofs, expect_cholmod);
    EXPECT_EQ(system.uses_cholmod(), expect_cholmod) << system.num_free_dofs() << " free DOFs";
  }
}

}  // namespace
}  // namespace taut
