// The co-rotated hex element's per-step kernels (plugin/corotated_hex_element.h) in both dense
// kernel sets (plugin/dense_kernels.h), one run: the rotated stiffness blocks scale R K_ab R^T and
// the product K_e u behind the forces and energy, over the 368 rotations of one pass of an
// armadillo-sized body, one shared K_e (a lattice's cells share it, ShareEqualHexStiffnesses).
// Time per iteration is one pass; median of 5 repetitions, so the generic / avx2 ratio of the
// medians is measured in one run.
//   taut_bench --benchmark_filter='BM_HexKernel'
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <random>
#include <vector>

#include "plugin/corotated_hex_element.h"
#include "plugin/dense_kernels.h"
#include "plugin/material.h"

namespace taut {
namespace {

constexpr int kElementCount = 368;

struct HexKernelInput {
  HexRestElement rest;
  std::vector<Mat3> rotations;
  std::vector<Vec24> displacements;
};

const HexKernelInput& Input() {
  static const HexKernelInput input = [] {
    HexNodes X;
    for (int a = 0; a < 8; ++a) X[a] = 0.05 * (HexCornerSign(a) + Vec3::Ones()) / 2.0;
    const Material material{1e5, 0.45, 1000.0};
    HexKernelInput out{CalcHexRestElement(X, {material.mu(), material.lambda()}), {}, {}};
    std::mt19937 rng(368);
    std::normal_distribution<double> n(0.0, 1.0);
    for (int e = 0; e < kElementCount; ++e) {
      const Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
      out.rotations.push_back(q.normalized().toRotationMatrix());
      out.displacements.push_back(1e-3 * Vec24::NullaryExpr([&] { return n(rng); }));
    }
    return out;
  }();
  return input;
}

const DenseKernels* KernelSet(int index) {
  return index == 0 ? &GenericDenseKernels() : Avx2DenseKernels();
}

// Times one pass of `kernel(kernels, input, element)` over the input's elements, in the set
// state.range(0) selects (0 generic, 1 avx2).
template <typename Kernel>
void RunHexKernel(benchmark::State& state, Kernel kernel) {
  const DenseKernels* kernels = KernelSet(static_cast<int>(state.range(0)));
  if (kernels == nullptr) return state.SkipWithError("this CPU or build has no AVX2 set");
  const HexKernelInput& input = Input();
  for (auto _ : state)
    for (int e = 0; e < kElementCount; ++e) kernel(*kernels, input, e);
  state.SetLabel(kernels->name);
}

void BM_HexKernelRotatedBlocks(benchmark::State& state) {
  HexStiffnessBlocks blocks;
  RunHexKernel(state, [&](const DenseKernels& kernels, const HexKernelInput& input, int e) {
    kernels.rotate_hex_stiffness_blocks(input.rest.stiffness().data(), input.rotations[e].data(),
                                        0.5, blocks[0].data());
    benchmark::DoNotOptimize(blocks);
  });
}

void BM_HexKernelStiffnessTimes(benchmark::State& state) {
  Vec24 Ku;
  RunHexKernel(state, [&](const DenseKernels& kernels, const HexKernelInput& input, int e) {
    kernels.multiply_hex_stiffness(input.rest.stiffness().data(), input.displacements[e].data(),
                                   Ku.data());
    benchmark::DoNotOptimize(Ku);
  });
}

BENCHMARK(BM_HexKernelRotatedBlocks)
    ->ArgName("avx2")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMicrosecond)
    ->Repetitions(5)
    ->ReportAggregatesOnly(true);
BENCHMARK(BM_HexKernelStiffnessTimes)
    ->ArgName("avx2")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMicrosecond)
    ->Repetitions(5)
    ->ReportAggregatesOnly(true);

}  // namespace
}  // namespace taut
