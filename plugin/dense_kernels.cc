#include "plugin/dense_kernels.h"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cstdlib>

#include "plugin/blas_core_check.h"
#include "plugin/common.h"

namespace taut {
namespace dense_generic {
#define TAUT_DENSE_KERNEL_SET_NAME "generic"
#include "plugin/dense_kernels_body.inc"
#undef TAUT_DENSE_KERNEL_SET_NAME
}  // namespace dense_generic

// Defined in dense_kernels_avx2.cc: the AVX2 table, or nullptr in a build without it.
const DenseKernels* GetAvx2DenseKernelTable();

const DenseKernels& GenericDenseKernels() { return dense_generic::kTable; }

const DenseKernels* Avx2DenseKernels() {
  static const DenseKernels* const avx2 =
      DetectCpuVectorSupport().avx2 ? GetAvx2DenseKernelTable() : nullptr;
  return avx2;
}

std::string ChooseDenseKernels(const std::string& requested, bool avx2_available) {
  if (requested.empty()) return avx2_available ? "avx2" : "generic";
  TAUT_DEMAND(requested == "generic" || requested == "avx2",
              "TAUT_DENSE_KERNELS: unknown dense kernel set '", requested,
              "' (expected 'generic' or 'avx2')");
  TAUT_DEMAND(requested == "generic" || avx2_available,
              "TAUT_DENSE_KERNELS=avx2: this CPU or build has no AVX2 + FMA kernels "
              "(use 'generic' or leave it unset)");
  return requested;
}

void SetEigenCacheSizes(const EigenCacheSizes& sizes) {
  GenericDenseKernels().set_cache_sizes(sizes.l1, sizes.l2, sizes.l3);
  // The AVX2 set's code runs only on a CPU with AVX2 (its setter is compiled for it too).
  if (const DenseKernels* avx2 = Avx2DenseKernels())
    avx2->set_cache_sizes(sizes.l1, sizes.l2, sizes.l3);
}

namespace {
// At load, before any product of the program (an object file of the library that every
// factorization links; plugin/dense_kernels.h, kEigenCacheSizes).
const bool kEigenCacheSizesSet = (SetEigenCacheSizes(kEigenCacheSizes), true);
}  // namespace

const DenseKernels& ActiveDenseKernels() {
  static const DenseKernels* const active = [] {
    const char* env = std::getenv("TAUT_DENSE_KERNELS");
    const bool avx2_available = Avx2DenseKernels() != nullptr;
    return ChooseDenseKernels(env ? env : "", avx2_available) == "avx2" ? Avx2DenseKernels()
                                                                        : &GenericDenseKernels();
  }();
  return *active;
}

}  // namespace taut
