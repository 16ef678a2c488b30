// SparseLdlt vs Eigen's SimplicialLDLT on the 3x3-block pattern of a box tet mesh: numeric
// factorization, one solve, 64 dense right-hand sides and 64 sparse (J^T-like) ones.
// Run with --benchmark_repetitions=9 --benchmark_report_aggregates_only=true for medians.
// Needs a main (link benchmark::benchmark_main).
#include <benchmark/benchmark.h>

#include <Eigen/SparseCholesky>
#include <array>
#include <map>
#include <random>
#include <vector>

#include "plugin/box_tet_mesher.h"
#include "plugin/sparse_ldlt.h"
#include "tests/tet_block_spd.h"

namespace taut {
namespace {

using SparseMatrix = SparseLdlt::SparseMatrix;

// One benchmark case: A = M + K with random SPD tet blocks on an nx x ny x nz-cell box
// (tests/tet_block_spd.h) and right-hand sides.
struct LdltCase {
  SparseMatrix A;
  VecX b;
  MatX B_dense;   // (dofs x 64) random
  MatX B_sparse;  // (dofs x 64) each column nonzero on the 12 dofs of one tet, like a row of J
};

// Builds (once per cell count) the matrix and right-hand sides.
const LdltCase& GetCase(int nx, int ny, int nz) {
  static std::map<std::array<int, 3>, LdltCase> cases;
  auto found = cases.find({nx, ny, nz});
  if (found != cases.end()) return found->second;
  const TetMesh mesh = MakeBoxTetMesh(Vec3(1, 1, 1), nx, ny, nz);
  LdltCase& out = cases[{nx, ny, nz}];
  out.A = testing::MakeRandomTetBlockSpd(nx, ny, nz, 1);
  const int n = static_cast<int>(out.A.rows());
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  out.b = VecX::NullaryExpr(n, [&] { return u(rng); });
  out.B_dense = MatX::NullaryExpr(n, 64, [&] { return u(rng); });
  out.B_sparse = MatX::Zero(n, 64);
  for (int c = 0; c < 64; ++c) {
    const auto& tet = mesh.tets[rng() % mesh.tets.size()];
    for (int a = 0; a < 4; ++a)
      for (int r = 0; r < 3; ++r) out.B_sparse(3 * tet[a] + r, c) = u(rng);
  }
  return out;
}

// Cell counts from the benchmark arguments.
const LdltCase& GetCase(const benchmark::State& state) {
  return GetCase(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)),
                 static_cast<int>(state.range(2)));
}

// What a benchmark times.
// kSolve1Single: one right-hand side through the single-precision copy of L (the kept-factor
// preconditioner's solve; the double solve for the up-looking kernel).
enum class Op { kFactor, kSolve1, kSolve1Single, kSolve64Dense, kSolve64Sparse };

// Times one operation with SparseLdlt and the given numeric kernel (kAuto: as a body gets it).
void RunTaut(benchmark::State& state, Op op, SparseLdlt::Kernel kernel) {
  const LdltCase& c = GetCase(state);
  SparseLdlt ldlt;
  ldlt.Analyze(c.A, kernel);
  if (!ldlt.Factorize(c.A)) state.SkipWithError("factorization failed");
  if (op == Op::kSolve1Single) ldlt.MakeSinglePrecisionCopy();
  VecX x = c.b;
  MatX X = c.B_dense;
  for (auto _ : state) {
    switch (op) {
      case Op::kFactor:
        benchmark::DoNotOptimize(ldlt.Factorize(c.A));
        break;
      case Op::kSolve1:
        x = c.b;
        ldlt.Solve(x);
        break;
      case Op::kSolve1Single:
        x = c.b;
        ldlt.SolveSinglePrecision(x);
        break;
      case Op::kSolve64Dense:
        X = c.B_dense;
        ldlt.SolveColumns(X);
        break;
      case Op::kSolve64Sparse:
        X = c.B_sparse;
        ldlt.SolveColumns(X);
        break;
    }
    benchmark::ClobberMemory();
  }
  state.counters["dofs"] = static_cast<double>(c.A.rows());
  state.counters["nnz_L"] = ldlt.nonzeros_in_L();
  state.counters["work"] = ldlt.CalcFactorWork();
  state.counters["supernodal"] = ldlt.supernodal() ? 1.0 : 0.0;
}

// Times one operation with Eigen::SimplicialLDLT (AMD ordering, lower triangle).
void RunEigen(benchmark::State& state, Op op) {
  const LdltCase& c = GetCase(state);
  Eigen::SimplicialLDLT<SparseMatrix> ldlt;
  ldlt.analyzePattern(c.A);
  ldlt.factorize(c.A);
  if (ldlt.info() != Eigen::Success) state.SkipWithError("factorization failed");
  VecX x = c.b;
  MatX X = c.B_dense;
  for (auto _ : state) {
    switch (op) {
      case Op::kFactor:
        ldlt.factorize(c.A);
        break;
      case Op::kSolve1:
      case Op::kSolve1Single:
        x = ldlt.solve(c.b);
        break;
      case Op::kSolve64Dense:
        X = ldlt.solve(c.B_dense);
        break;
      case Op::kSolve64Sparse:
        X = ldlt.solve(c.B_sparse);
        break;
    }
    benchmark::ClobberMemory();
  }
  state.counters["dofs"] = static_cast<double>(c.A.rows());
  state.counters["nnz_L"] = static_cast<double>(ldlt.matrixL().nestedExpression().nonZeros());
}

// 6x6x8 cells: 441 nodes, 1,323 dofs. 14x14x14 cells: 3,375 nodes, 10,125 dofs.
#define TAUT_LDLT_SIZES ->Args({6, 6, 8})->Args({14, 14, 14})->Unit(benchmark::kMicrosecond)

using Kernel = SparseLdlt::Kernel;
BENCHMARK_CAPTURE(RunTaut, Factor, Op::kFactor, Kernel::kAuto) TAUT_LDLT_SIZES;
BENCHMARK_CAPTURE(RunEigen, Factor, Op::kFactor) TAUT_LDLT_SIZES;
BENCHMARK_CAPTURE(RunTaut, Solve1, Op::kSolve1, Kernel::kAuto) TAUT_LDLT_SIZES;
BENCHMARK_CAPTURE(RunEigen, Solve1, Op::kSolve1) TAUT_LDLT_SIZES;
BENCHMARK_CAPTURE(RunTaut, Solve1Single, Op::kSolve1Single, Kernel::kAuto) TAUT_LDLT_SIZES;
BENCHMARK_CAPTURE(RunTaut, Solve64Dense, Op::kSolve64Dense, Kernel::kAuto) TAUT_LDLT_SIZES;
BENCHMARK_CAPTURE(RunEigen, Solve64Dense, Op::kSolve64Dense) TAUT_LDLT_SIZES;
BENCHMARK_CAPTURE(RunTaut, Solve64Sparse, Op::kSolve64Sparse, Kernel::kAuto) TAUT_LDLT_SIZES;
BENCHMARK_CAPTURE(RunEigen, Solve64Sparse, Op::kSolve64Sparse) TAUT_LDLT_SIZES;

// Both kernels over a range of sizes, for SparseLdlt::kSupernodalMinWork (the work counter says
// where each size falls): 3x3x3 cells (192 dofs) to 14x14x14.
#define TAUT_KERNEL_SIZES  \
  ->Args({3, 3, 3})        \
      ->Args({4, 4, 4})    \
      ->Args({5, 5, 6})    \
      ->Args({6, 6, 8})    \
      ->Args({8, 8, 8})    \
      ->Args({10, 10, 10}) \
      ->Args({20, 4, 4})   \
      ->Args({14, 14, 14}) \
      ->Unit(benchmark::kMicrosecond)
BENCHMARK_CAPTURE(RunTaut, FactorUpLooking, Op::kFactor, Kernel::kUpLooking) TAUT_KERNEL_SIZES;
BENCHMARK_CAPTURE(RunTaut, FactorSupernodal, Op::kFactor, Kernel::kSupernodal) TAUT_KERNEL_SIZES;
BENCHMARK_CAPTURE(RunTaut, Solve64SparseUpLooking, Op::kSolve64Sparse, Kernel::kUpLooking)
TAUT_KERNEL_SIZES;
BENCHMARK_CAPTURE(RunTaut, Solve64SparseSupernodal, Op::kSolve64Sparse, Kernel::kSupernodal)
TAUT_KERNEL_SIZES;
BENCHMARK_CAPTURE(RunTaut, Solve1UpLooking, Op::kSolve1, Kernel::kUpLooking) TAUT_KERNEL_SIZES;
BENCHMARK_CAPTURE(RunTaut, Solve1Supernodal, Op::kSolve1, Kernel::kSupernodal) TAUT_KERNEL_SIZES;

}  // namespace
}  // namespace taut
