// Allocation-free sparse LDL^T factorization for the body's implicit-step matrix.
#pragma once

#include <Eigen/SparseCore>
#include <utility>
#include <vector>

#include "plugin/common.h"
#include "plugin/sparse_columns.h"
#include "plugin/supernodal_cholesky.h"

namespace taut {

// Sparse P A P^T = L D L^T of a symmetric matrix A (L unit lower triangular, D diagonal, P a
// fill-reducing permutation: AMD, or nested dissection for large bodies), for A = M + h D + h^2 K
// of the implicit step (docs/math.md §5.1;
// docs/architecture.md §3, stage 2). The pattern of A is fixed per body while its values change
// every step, so the work is split into a symbolic phase (Analyze, once per body: ordering,
// elimination tree, column counts, every buffer) and a numeric phase (Factorize, every step) plus
// solves that never touch the heap.
//
// Algorithm: Davis' up-looking "LDL" (T. A. Davis, "Algorithm 849: a concise sparse Cholesky
// factorization package", ACM TOMS 31(4), 2005). Row k of L solves L(0:k,0:k) D l = A(0:k,k) with
// the pattern of l given by the elimination-tree paths from the nonzeros of A(0:k,k) to k.
//
// Input: a square CSC (column-major, compressed) matrix. Only its upper triangle (row <= col) is
// read, so it may hold the upper triangle or the full symmetric matrix; entries below the diagonal
// are ignored (their symmetry is not checked).
//
// D may have negative entries: Factorize succeeds for any A whose leading principal minors of
// P A P^T are nonzero and reports the number of negative pivots, which equals the number of
// negative eigenvalues of A (Sylvester's law of inertia), so callers can detect an indefinite A.
//
// Large matrices take the supernodal kernel instead (SupernodalCholesky: dense blocks, the same
// ordering and elimination tree): from kSupernodalMinWork multiply-adds of factorization work,
// where it is faster (measured in bench/sparse_ldlt_bench.cc). It factors SPD matrices only: an
// indefinite A fails there at its first non-positive pivot instead of counting negative pivots.
//
// Not thread-safe: Solve and SolveColumns share a workspace inside the object.
class SparseLdlt {
 public:
  using SparseMatrix = Eigen::SparseMatrix<double>;  // column-major, int indices

  // Numeric kernel: chosen by size (kAuto), or forced.
  enum class Kernel { kAuto, kUpLooking, kSupernodal };
  // Factorization work (CalcFactorWork) from which kAuto picks the supernodal kernel.
  static constexpr double kSupernodalMinWork = 1e5;
  // Fill-reducing ordering: chosen (kAuto: AMD, and where AMD's factor work is at least
  // kNestedDissectionMinWork, about 5k-tet bodies, nested dissection instead when its factor has
  // at most kNestedDissectionWorkRatio times the work and no more nonzeros), or forced.
  enum class Ordering { kAuto, kAmd, kNestedDissection };
  static constexpr double kNestedDissectionMinWork = 3e7;
  static constexpr double kNestedDissectionWorkRatio = 0.85;

  // Largest number of right-hand sides SolveColumns carries through one pass over L.
  static constexpr int kMaxBlockColumns = 16;

  // Symbolic phase: the ordering of the symmetric pattern (AMD; nested dissection instead where it
  // saves enough factor work, see Ordering), elimination tree, column counts of L,
  // the map from A's values to the permuted upper triangle, and every workspace. Values are
  // ignored. Throws InputError for a non-square, empty or uncompressed matrix.
  void Analyze(const SparseMatrix& pattern, Kernel kernel = Kernel::kAuto,
               Ordering ordering = Ordering::kAuto);
  // True when Analyze chose (or was given) the supernodal kernel.
  bool supernodal() const { return supernodal_; }
  // The supernodal kernel's factor (its split, plugin/supernodal_cholesky.h).
  const SupernodalCholesky& supernodal_factor() const { return supernodal_factor_; }
  // The ordering Analyze chose (kAmd or kNestedDissection).
  Ordering ordering() const { return ordering_; }

  // Numeric phase on a matrix with the analysed pattern (same outer index and nonzero count; the
  // row indices are compared in debug builds). No heap allocation (the supernodal kernel's dense
  // products allocate a few work blocks). Returns false when a pivot is
  // zero or not finite; failed_column() then names the column of A. Throws InputError when called
  // before Analyze or with a different size or nonzero count. A runner of two or more threads
  // factors the supernodal kernel's two subtree groups in parallel (SupernodalCholesky::Factorize;
  // bitwise the same factor).
  bool Factorize(const SparseMatrix& A, ElementLoopRunner* runner = nullptr);

  // Solves A x = b in place (b := x). No heap allocation. Throws InputError without a successful
  // Factorize or when b has the wrong size.
  void Solve(Eigen::Ref<VecX> b) const;

  // Preconditioner solves: MakeSinglePrecisionCopy keeps fl32(L) of a supernodal factor (after
  // Factorize; nothing for the up-looking kernel, whose bodies are small), and
  // SolveSinglePrecision solves with it, exactly for L_f L_f^T in double arithmetic at half the
  // memory traffic of Solve; without a current copy it is Solve. Same errors as Solve.
  void MakeSinglePrecisionCopy();
  void SolveSinglePrecision(Eigen::Ref<VecX> b) const;

  // Solves A X = B in place for every column of B (B := X), carrying up to kMaxBlockColumns
  // columns through each pass over L. No heap allocation. Same errors as Solve.
  void SolveColumns(Eigen::Ref<MatX> B) const;

  // The halves of A^-1 for Delassus operators (docs/math.md §5.7): with A = P^T L D L^T P,
  // B^T A^-1 B = Z^T Z for Z = D^-1/2 L^-1 P B. HalfSolveColumns: Z (n x B.cols(), rows in
  // elimination order) for the sparse columns B (indices are rows of A); the forward solve skips
  // the rows where a block of B is zero, so a sparse column costs its elimination-tree path only.
  // CompleteHalfSolve: z := P^T L^-T D^-1/2 z, so that CompleteHalfSolve(Z c) = A^-1 B c. Both
  // need positive pivots (InputError otherwise) and allocate nothing; same errors as Solve.
  void HalfSolveColumns(const SparseColumns& B, Eigen::Ref<MatX> Z) const;
  void CompleteHalfSolve(Eigen::Ref<VecX> z) const;

  // Number of rows (and columns) of A.
  int rows() const { return n_; }
  // Nonzeros of L strictly below the diagonal (the unit diagonal is not stored).
  int nonzeros_in_L() const { return analyzed_ ? col_start_[n_] : 0; }
  // Multiply-adds of one Factorize, sum_j c_j (c_j + 3) / 2 with c_j = nonzeros of column j of L
  // (the left-looking update of each column by its row pattern); 0 before Analyze.
  double CalcFactorWork() const;
  // (n) perm[k] = column of A eliminated k-th, i.e. (P A P^T)(k, j) = A(perm[k], perm[j]).
  const std::vector<int>& permutation() const { return perm_; }
  // True after Analyze.
  bool analyzed() const { return analyzed_; }
  // True after a Factorize that returned true (and no Analyze since).
  bool factorized() const { return factorized_; }
  // Column of A whose pivot was zero or not finite in the last Factorize; -1 if none.
  int failed_column() const { return failed_column_; }
  // Number of negative entries of D in the last Factorize (up to the failed pivot on failure).
  int num_negative_pivots() const { return num_negative_pivots_; }
  // (n) the pivots D in elimination order (valid after a successful Factorize).
  const std::vector<double>& pivots() const { return d_; }

 private:
  // perm_ = order (new -> old), then C and the elimination tree for it.
  void AnalyzeOrdering(const SparseMatrix& pattern, const std::vector<int>& order);
  // Analyzes the nested-dissection ordering and keeps it when it saves enough over AMD's factor
  // (analyzed on entry; see Ordering), else analyzes `amd_order` again.
  void ChooseNestedDissection(const SparseMatrix& pattern, const std::vector<int>& amd_order);
  // Builds the permuted upper triangle C = triu(P A P^T) as structure plus a map into A's values.
  void BuildPermutedUpper(const SparseMatrix& pattern);
  // Elimination tree of C and the nonzero count of every column of L (Davis' LDL symbolic).
  void CalcEliminationTree();
  // Solves for kWidth columns stored at b + c * outer_stride, c = 0..kWidth-1.
  template <int kWidth>
  void SolveBlock(double* b, Eigen::Index outer_stride) const;
  // The workspace's rows (n x kWidth, row-major) through L^-1, and through L^-T.
  template <int kWidth>
  void SolveLowerBlock() const;
  template <int kWidth>
  void SolveLowerTransposedBlock() const;
  // Solves through the supernodal factor for `width` columns (gather P B, solve, scatter).
  void SolveSupernodal(double* b, Eigen::Index outer_stride, int width) const;
  // Throws InputError unless a factorization is ready for right-hand sides with `size` rows.
  void DemandReadyToSolve(Eigen::Index size) const;

  int n_ = 0;
  bool analyzed_ = false;
  bool factorized_ = false;
  int failed_column_ = -1;
  int num_negative_pivots_ = 0;
  bool supernodal_ = false;
  Ordering ordering_ = Ordering::kAmd;
  SupernodalCholesky supernodal_factor_;  // the factor when supernodal_

  // Ordering.
  std::vector<int> perm_;   // (n) new -> old
  std::vector<int> iperm_;  // (n) old -> new

  // Pattern of A as analysed, to check the matrices handed to Factorize.
  std::vector<int> a_outer_;  // (n + 1) column starts of A
  std::vector<int> a_inner_;  // (nnz(A)) row indices of A

  // C = triu(P A P^T) in CSC; its values are read from A through c_source_ (no copy).
  std::vector<int> c_start_;   // (n + 1) column starts
  std::vector<int> c_row_;     // (nnz(C)) row indices, each <= its column
  std::vector<int> c_source_;  // (nnz(C)) index into A.valuePtr() of each entry

  // Elimination tree and L in CSC (strictly lower part, rows ascending within a column).
  std::vector<int> parent_;     // (n) etree parent, -1 at a root
  std::vector<int> col_start_;  // (n + 1) column starts of L
  std::vector<int> l_row_;      // (nnz(L)) row indices of L
  std::vector<double> l_val_;   // (nnz(L)) values of L
  std::vector<double> d_;       // (n) pivots D
  std::vector<double> d_inv_;   // (n) 1 / D

  // Factorize workspace: dense row accumulator (all zero between rows), visit flags, pattern stack
  // and the current fill of each column of L.
  std::vector<double> y_;      // (n)
  std::vector<int> flag_;      // (n)
  std::vector<int> stack_;     // (n)
  std::vector<int> col_fill_;  // (n)

  // Solve workspace: (n x kMaxBlockColumns) row-major, so one row of a block is contiguous.
  mutable std::vector<double> work_;
  // HalfSolveColumns: (first nonzero in elimination order, column) of each right-hand side.
  mutable std::vector<std::pair<int, int>> half_order_;
};

}  // namespace taut
