// Supernodal sparse Cholesky (CHOLMOD) for the implicit-step matrix of large bodies.
#pragma once

#include <Eigen/SparseCore>
#include <memory>
#include <vector>

#include "plugin/common.h"

namespace taut {

// True when this build of taut links CHOLMOD. CHOLMOD's supernodal module is GPL-2+, so it is
// opt-in (CMake option TAUT_WITH_CHOLMOD, off by default); without it every CholmodCholesky member
// that would factor or solve throws InputError saying so.
bool IsCholmodAvailable();

namespace internal {
struct CholmodState;
// Frees the CHOLMOD factor and workspace of a state (defined next to CholmodState).
struct CholmodStateDeleter {
  void operator()(CholmodState* state) const;
};
}  // namespace internal

// Sparse P A P^T = L L^T of a symmetric positive definite A (L lower triangular with a positive
// diagonal, P a fill-reducing permutation), for A = M + h D + h^2 K of the implicit step
// (docs/math.md §5.1) of bodies too large for SparseLdlt.
//
// Algorithm: CHOLMOD's supernodal left-looking Cholesky (Y. Chen, T. A. Davis, W. W. Hager,
// S. Rajamanickam, "Algorithm 887: CHOLMOD, supernodal sparse Cholesky factorization and
// update/downdate", ACM TOMS 35(3), 2008). Adjacent columns of L with the same pattern form a
// supernode, stored and factored as one dense block with BLAS-3 and LAPACK (dsyrk, dgemm, dpotrf),
// so most flops run at dense-matrix speed; the 3 DOFs of a node always share a pattern, so
// supernodes are at least 3 wide. Ordering: CHOLMOD's default, AMD, then METIS nested dissection
// when AMD's fill is high (large 3D meshes), keeping the one with fewer flops.
//
// Same phases and input convention as SparseLdlt: Analyze once per pattern, Factorize every step;
// a square CSC matrix of which only the upper triangle (row <= col) is read.
//
// Heap: Analyze sizes every buffer the solves use, so Solve and SolveColumns do not allocate.
// Factorize does: CHOLMOD builds the permuted copy of A and its dense update workspace on every
// call (a few allocations, O(nnz(A) + largest update block) bytes). ImplicitSystem therefore uses
// this class only above its size threshold, where those allocations cost nothing next to the
// factorization's flops, and keeps the allocation-free SparseLdlt for small bodies.
//
// LL^T needs A positive definite: Factorize returns false at the first pivot that is not positive
// (or on a non-finite entry of A). There is no inertia count as in SparseLdlt.
//
// Threads: Factorize runs CHOLMOD serially by switching the process's OpenMP runtime (which
// Debian's CHOLMOD brings) to inactive parallel regions for the call; the BLAS should be a serial
// one (scripts/install_deps.sh installs OpenBLAS's serial build). Not thread-safe: Solve and
// SolveColumns share a workspace and CHOLMOD's status inside the object. Movable, not copyable.
class CholmodCholesky {
 public:
  using SparseMatrix = Eigen::SparseMatrix<double>;  // column-major, int indices

  // Largest number of right-hand sides SolveColumns carries through one pass over L. Wider blocks
  // make the triangular solves BLAS-3 (64 vs 16: 40 -> 29 ms for 64 columns at 12.6k DOFs) at
  // 8 * 64 bytes of workspace per DOF (30 MB at 58k DOFs, next to 240 MB for L).
  static constexpr int kMaxBlockColumns = 64;

  CholmodCholesky();
  ~CholmodCholesky();
  CholmodCholesky(CholmodCholesky&&) noexcept;
  CholmodCholesky& operator=(CholmodCholesky&&) noexcept;

  // Symbolic phase: ordering, supernodal elimination tree and pattern of L, solve workspace.
  // Values are ignored. Throws InputError for a non-square, empty or uncompressed matrix or when
  // the build has no CHOLMOD (IsCholmodAvailable() false), SimulationError when CHOLMOD fails (out
  // of memory, L too large for int indices).
  void Analyze(const SparseMatrix& pattern);

  // Numeric phase on a matrix with the analysed pattern (same outer index and nonzero count; the
  // row indices are compared in debug builds). Allocates (see the class comment). Returns false
  // when A is not positive definite or has a non-finite entry in its upper triangle;
  // failed_column() then names the column of A. Throws InputError when called before Analyze or
  // with a different size or nonzero count, SimulationError when CHOLMOD runs out of memory.
  bool Factorize(const SparseMatrix& A);

  // Solves A x = b in place (b := x). No heap allocation. Throws InputError without a successful
  // Factorize or when b has the wrong size.
  void Solve(Eigen::Ref<VecX> b) const;

  // Solves A X = B in place for every column of B (B := X), kMaxBlockColumns columns per pass over
  // L (BLAS-3 triangular solves). No heap allocation. Same errors as Solve.
  void SolveColumns(Eigen::Ref<MatX> B) const;

  // Number of rows (and columns) of A.
  int rows() const { return n_; }
  // Entries of L as stored (supernodes are dense trapezoids, so this counts the explicit zeros
  // that make them dense and the diagonal).
  double stored_entries_in_L() const;
  // Number of supernodes (0 before Analyze).
  int num_supernodes() const;
  // (n) perm[k] = column of A eliminated k-th, i.e. (P A P^T)(k, j) = A(perm[k], perm[j]).
  const std::vector<int>& permutation() const { return perm_; }
  // True after Analyze.
  bool analyzed() const { return analyzed_; }
  // True after a Factorize that returned true (and no Analyze since).
  bool factorized() const { return factorized_; }
  // Column of A whose pivot was not positive (or that holds a non-finite entry) in the last
  // Factorize; -1 if none.
  int failed_column() const { return failed_column_; }

 private:
  // x = P^T L^-T L^-1 P b for `width` <= kMaxBlockColumns columns at b + c * outer_stride.
  void SolveBlock(double* b, Eigen::Index outer_stride, int width) const;
  // Throws InputError unless a factorization is ready for right-hand sides with `size` rows.
  void DemandReadyToSolve(Eigen::Index size) const;

  int n_ = 0;
  bool analyzed_ = false;
  bool factorized_ = false;
  int failed_column_ = -1;

  std::vector<int> perm_;     // (n) new -> old, copied from the CHOLMOD factor
  std::vector<int> a_outer_;  // (n + 1) column starts of A as analysed
  std::vector<int> a_inner_;  // (nnz(A)) row indices of A as analysed

  // CHOLMOD's common block, the factor and the solve workspace: (n x kMaxBlockColumns)
  // column-major Y = P B and (kMaxBlockColumns x largest off-diagonal supernode height) E.
  std::unique_ptr<internal::CholmodState, internal::CholmodStateDeleter> state_;
};

}  // namespace taut
