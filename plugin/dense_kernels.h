// The dense kernels of the sparse factorization and of the dual path's Delassus blocks, compiled
// twice and chosen once per process by the CPU: a generic x86-64 (SSE2) build, and on x86-64 an
// AVX2 + FMA build of the same source (plugin/dense_kernels_body.inc). Debian packages are built
// for the generic ISA; these kernels are where the wider vectors pay (factor + solve of the
// 368-hex armadillo 2.3 -> 1.4 ms, of a 100k-tet beam 2.4 -> 1.2 s, AMD EPYC; README), and the
// single-precision panel solves of a kept factor's CG (bench/tet_scaling_bench.cc).
//
// All matrices are column-major with a leading dimension (ld >= rows); blocks of right-hand sides
// of the supernodal solves are row-major with `cols` entries per row. The two builds round
// differently (FMA), so results are bitwise reproducible for one kernel set: determinism pins are
// kept per set (tests/data/determinism_hashes.txt). Within a set they are the same on every CPU:
// Eigen's blocking is fixed (kEigenCacheSizes below).
//
// TAUT_DENSE_KERNELS=generic (or avx2) in the environment forces a set; an unknown name, or avx2
// on a CPU or build without it, throws InputError at the first use.
#pragma once

#include <cstddef>
#include <string>

namespace taut {

struct DenseKernels {
  const char* name;  // "generic" or "avx2"
  // C (m x n) = A (m x k) B (n x k)^T.
  void (*multiply_by_transposed)(const double* a, int lda, const double* b, int ldb, int m, int n,
                                 int k, double* c, int ldc);
  // In place A (n x n, lower triangle) = L with L L^T = A (blocked Cholesky). Returns the first
  // column whose pivot is not positive, or -1.
  int (*cholesky_lower)(double* a, int lda, int n);
  // B (m x n) = B L^-T for the lower-triangular L (n x n).
  void (*solve_right_lower_transposed)(const double* l, int ldl, int n, double* b, int ldb, int m);
  // One supernode of the forward solve: y_s (w x cols, row-major) = L_tt^-1 y_s, then
  // t (below x cols, row-major) = L_below y_s; L_tt is rows [0, w) of the panel l (ld ldl),
  // L_below rows [w, w + below).
  void (*forward_supernode)(const double* l, int ldl, int w, int below, double* y_s, int cols,
                            double* t);
  // One supernode of the backward solve: y_s -= L_below^T t (when below > 0), then
  // y_s = L_tt^-T y_s.
  void (*backward_supernode)(const double* l, int ldl, int w, int below, double* y_s, int cols,
                             const double* t);
  // out (m x k) = a^T b for a (d x m) and b (d x k), the depth d summed in chunks of
  // kDenseProductDepthChunk in a fixed order.
  void (*multiply_transposed_by_chunks)(const double* a, int lda, const double* b, int ldb, int d,
                                        int m, int k, double* out, int ldo);
  // out (m x m) = a^T a, both triangles, by rank updates of kDenseProductDepthChunk rows.
  void (*gram_by_chunks)(const double* a, int lda, int d, int m, double* out, int ldo);
  // The single-precision solve of a kept factor (supernodal_cholesky.h), one panel (m rows, w
  // columns, column-major fl32 L) on a dense u (m) in double: forward u_t = L_tt^-1 u_t,
  // u_rest -= L_rest u_t; backward u_t = L_tt^-T (u_t - L_rest^T u_rest).
  void (*forward_panel_single)(const float* l, int m, int w, double* u);
  void (*backward_panel_single)(const float* l, int m, int w, double* u);
  // The co-rotated hex element (corotated_hex_element.h), K_e 24 x 24 column-major: Ku = K_e u
  // (its forces and energy), and blocks (64 column-major 3x3, (a, b) at 9 (8 a + b)) =
  // scale R K_ab R^T for a <= b, the blocks below their transposes (K_e symmetric).
  void (*multiply_hex_stiffness)(const double* K, const double* u, double* Ku);
  void (*rotate_hex_stiffness_blocks)(const double* K, const double* R, double scale,
                                      double* blocks);
  // The cache sizes (bytes) this set's Eigen blocks its products and triangular solves for:
  // set, and the L1 size in effect.
  void (*set_cache_sizes)(std::ptrdiff_t l1, std::ptrdiff_t l2, std::ptrdiff_t l3);
  std::ptrdiff_t (*l1_cache_size)();
};

// Eigen sizes the blocks of its matrix products and triangular solves from the cache sizes the
// CPU reports, and the block over a product's depth (from L1) sets its summation order: the same
// factorization rounded differently on an Intel Xeon (48 KiB L1d) than on an AMD EPYC (32 KiB),
// and the finger, box_on_sphere and gripper scenes changed their pinned state hashes between the
// two. taut sets these sizes in both kernel sets when it loads (the generic set's Eigen is the
// one the rest of taut, and a program linking taut, uses), so results are the same bits on every
// x86-64 CPU. They are the AMD EPYC's, on which the pins were made.
struct EigenCacheSizes {
  std::ptrdiff_t l1, l2, l3;
};
inline constexpr EigenCacheSizes kEigenCacheSizes{32 * 1024, 512 * 1024, 32 * 1024 * 1024};
// Sets the cache sizes of every kernel set this CPU can run (at load: kEigenCacheSizes).
void SetEigenCacheSizes(const EigenCacheSizes& sizes);

// Eigen splits a product's depth into blocks sized from the CPU's L1 cache and sums the partial
// results, so a deep product's last bits would depend on the machine; the Delassus products sum
// chunks of this depth in a fixed order instead (the same bits on every CPU of one kernel set).
constexpr int kDenseProductDepthChunk = 256;

// The set this process uses (chosen at the first call: TAUT_DENSE_KERNELS, else avx2 when the
// CPU has AVX2 and FMA and the build has the set, else generic).
const DenseKernels& ActiveDenseKernels();
// The generic set, and the AVX2 + FMA set or nullptr (not an x86-64 build, or the CPU lacks it).
const DenseKernels& GenericDenseKernels();
const DenseKernels* Avx2DenseKernels();
// The choice for `requested` (the value of TAUT_DENSE_KERNELS, "" when unset) on a CPU that
// has (`avx2_available`) the AVX2 set; throws InputError for an unknown or unavailable name.
std::string ChooseDenseKernels(const std::string& requested, bool avx2_available);

}  // namespace taut
