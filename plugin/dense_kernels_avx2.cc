// The AVX2 + FMA build of the dense kernels (plugin/dense_kernels.h). CMake compiles this file
// with -mavx2 -mfma on x86-64 (TAUT_DENSE_AVX2); the table is used only after the CPU reported
// both extensions. Eigen's namespace is renamed for this file: its templates instantiated here
// (AVX2 code) must not merge at link time with the generic instances of the rest of taut.
#include "plugin/dense_kernels.h"

#if TAUT_DENSE_AVX2
#include <algorithm>

#define Eigen taut_avx2_Eigen
#include <Eigen/Cholesky>
#include <Eigen/Core>

namespace taut {
namespace dense_avx2 {
#define TAUT_DENSE_KERNEL_SET_NAME "avx2"
#include "plugin/dense_kernels_body.inc"
#undef TAUT_DENSE_KERNEL_SET_NAME
}  // namespace dense_avx2

const DenseKernels* GetAvx2DenseKernelTable() { return &dense_avx2::kTable; }
}  // namespace taut

#else
namespace taut {
const DenseKernels* GetAvx2DenseKernelTable() { return nullptr; }
}  // namespace taut
#endif
