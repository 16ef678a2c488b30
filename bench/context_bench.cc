// Context recorded with every run of taut_bench (Google Benchmark's "context" in its JSON): the
// dense kernel set the process runs (plugin/dense_kernels.h), which scripts/run_bench.sh writes
// beside the CPU model, since the factorization's speed depends on it.
#include <benchmark/benchmark.h>

#include "plugin/dense_kernels.h"

namespace taut {
namespace {

const bool kDenseKernelsRecorded =
    (benchmark::AddCustomContext("dense_kernels", ActiveDenseKernels().name), true);

}  // namespace
}  // namespace taut
