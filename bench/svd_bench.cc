// The signed SVD of 3x3 deformation gradients: taut's CalcSignedSvd (plugin/signed_svd.h, Jacobi
// on G^T G + Givens QR) against Eigen's JacobiSVD with full U and V plus the same sign fix
// (docs/math.md §0.2), over one fixed set of 1024 gradients I + 0.1 X (X uniform in [-1, 1]^9;
// every 8th one inverted by a negated column). Time per iteration is one pass over all 1024;
// median of 5 repetitions, so the ratio of the two medians is measured in one run. The element
// rotation on the same set: CalcPolarRotation (plugin/polar_rotation.h, Newton's iteration; the
// inverted eighth falls back to the SVD) against U V^T of CalcSignedSvd.
//   taut_bench --benchmark_filter='BM_SignedSvd|BM_EigenJacobiSvd|BM_PolarRotation'
#include <benchmark/benchmark.h>

#include <Eigen/LU>
#include <Eigen/SVD>
#include <random>
#include <vector>

#include "plugin/polar_rotation.h"
#include "plugin/signed_svd.h"

namespace taut {
namespace {

constexpr int kGradientCount = 1024;

// The fixed set of near-identity deformation gradients, some inverted.
const std::vector<Mat3>& Gradients() {
  static const std::vector<Mat3> gradients = [] {
    std::mt19937 rng(2011);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<Mat3> out(kGradientCount);
    for (int i = 0; i < kGradientCount; ++i) {
      Mat3 X;
      for (int k = 0; k < 9; ++k) X.data()[k] = u(rng);
      out[i] = Mat3::Identity() + 0.1 * X;
      if (i % 8 == 0) out[i].col(i % 3) *= -1.0;
    }
    return out;
  }();
  return gradients;
}

// Eigen's SVD with the sign fix of docs/math.md §0.2 (what CalcSignedSvd computed before).
SignedSvd EigenSignedSvd(const Mat3& G) {
  Eigen::JacobiSVD<Mat3> svd(G, Eigen::ComputeFullU | Eigen::ComputeFullV);
  SignedSvd out{svd.matrixU(), svd.singularValues(), svd.matrixV()};
  if (out.U.determinant() < 0.0) {
    out.U.col(2) *= -1.0;
    out.s[2] *= -1.0;
  }
  if (out.V.determinant() < 0.0) {
    out.V.col(2) *= -1.0;
    out.s[2] *= -1.0;
  }
  return out;
}

template <auto Decompose>
void RunSvd(benchmark::State& state) {
  const std::vector<Mat3>& gradients = Gradients();
  for (auto _ : state) {
    for (const Mat3& G : gradients) {
      auto result = Decompose(G);
      benchmark::DoNotOptimize(result);
    }
  }
  state.SetItemsProcessed(state.iterations() * kGradientCount);
}

void BM_SignedSvd(benchmark::State& state) { RunSvd<CalcSignedSvd>(state); }
void BM_EigenJacobiSvd(benchmark::State& state) { RunSvd<EigenSignedSvd>(state); }
void BM_PolarRotation(benchmark::State& state) { RunSvd<CalcPolarRotation>(state); }
void BM_PolarRotationBySvd(benchmark::State& state) { RunSvd<CalcPolarRotationBySvd>(state); }

// Microseconds per pass, medians of 5 repetitions.
void MediansOfFive(benchmark::internal::Benchmark* b) {
  b->Unit(benchmark::kMicrosecond)->Repetitions(5)->ReportAggregatesOnly(true);
}

BENCHMARK(BM_SignedSvd)->Apply(MediansOfFive);
BENCHMARK(BM_EigenJacobiSvd)->Apply(MediansOfFive);
BENCHMARK(BM_PolarRotation)->Apply(MediansOfFive);
BENCHMARK(BM_PolarRotationBySvd)->Apply(MediansOfFive);

}  // namespace
}  // namespace taut
