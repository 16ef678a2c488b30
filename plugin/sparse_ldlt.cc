#include "plugin/sparse_ldlt.h"

#include <Eigen/OrderingMethods>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "plugin/nested_dissection.h"

namespace taut {

// Symbolic phase: validate, order (AMD or nested dissection), permute the pattern, etree and column
// counts, buffers.
void SparseLdlt::Analyze(const SparseMatrix& pattern, Kernel kernel, Ordering ordering) {
  analyzed_ = false;
  factorized_ = false;
  failed_column_ = -1;
  num_negative_pivots_ = 0;
  TAUT_DEMAND(pattern.rows() == pattern.cols(), "SparseLdlt::Analyze: matrix must be square, got ",
              pattern.rows(), "x", pattern.cols());
  TAUT_DEMAND(pattern.rows() > 0, "SparseLdlt::Analyze: matrix is empty");
  TAUT_DEMAND(pattern.isCompressed(),
              "SparseLdlt::Analyze: matrix must be compressed (call makeCompressed())");
  n_ = static_cast<int>(pattern.rows());
  const int nnz_a = static_cast<int>(pattern.nonZeros());
  a_outer_.assign(pattern.outerIndexPtr(), pattern.outerIndexPtr() + n_ + 1);
  a_inner_.assign(pattern.innerIndexPtr(), pattern.innerIndexPtr() + nnz_a);

  // AMD on the symmetric pattern triu(A) + triu(A)^T. Eigen returns the inverse permutation:
  // indices()(k) is the old index of the k-th pivot (SimplicialCholesky uses it the same way).
  analyzed_ = true;
  if (ordering == Ordering::kNestedDissection) {
    AnalyzeOrdering(pattern, CalcNestedDissectionOrdering(pattern, /*blocks_of_three=*/true));
    ordering_ = Ordering::kNestedDissection;
  } else {
    Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> new_to_old;
    Eigen::AMDOrdering<int> amd;
    amd(pattern.selfadjointView<Eigen::Upper>(), new_to_old);
    std::vector<int> amd_order(new_to_old.indices().data(), new_to_old.indices().data() + n_);
    AnalyzeOrdering(pattern, amd_order);
    ordering_ = Ordering::kAmd;
    if (ordering == Ordering::kAuto && CalcFactorWork() >= kNestedDissectionMinWork)
      ChooseNestedDissection(pattern, amd_order);
  }
  supernodal_ = kernel == Kernel::kSupernodal ||
                (kernel == Kernel::kAuto && CalcFactorWork() >= kSupernodalMinWork);

  // Every buffer the numeric phase and the solves touch, sized once here; the up-looking
  // kernel's L and row workspace only when that kernel runs (the supernodal one keeps its panels).
  const int nnz_l = supernodal_ ? 0 : col_start_[n_];
  const int n_up = supernodal_ ? 0 : n_;
  l_row_.assign(nnz_l, 0);
  l_val_.assign(nnz_l, 0.0);
  d_.assign(n_, 0.0);
  d_inv_.assign(n_up, 0.0);
  y_.assign(n_up, 0.0);
  flag_.assign(n_up, -1);
  stack_.assign(n_up, 0);
  col_fill_.assign(n_up, 0);
  work_.assign(static_cast<size_t>(n_) * kMaxBlockColumns, 0.0);
  supernodal_factor_ = SupernodalCholesky();
  if (supernodal_) supernodal_factor_.Analyze(n_, c_start_, c_row_, c_source_, parent_, col_start_);
}

void SparseLdlt::AnalyzeOrdering(const SparseMatrix& pattern, const std::vector<int>& order) {
  perm_ = order;
  iperm_.assign(n_, -1);
  for (int k = 0; k < n_; ++k) iperm_[perm_[k]] = k;
  BuildPermutedUpper(pattern);
  CalcEliminationTree();
}

void SparseLdlt::ChooseNestedDissection(const SparseMatrix& pattern,
                                        const std::vector<int>& amd_order) {
  // Large 3D meshes fill less under nested dissection than under AMD: the supernodal
  // factor + solve of the 100k-tet cantilever took 0.62x the time at 0.57x the work and 0.75x the
  // nonzeros. A smaller gain in work did not show in time (20k and 25k tets: 0.90x and 0.97x the
  // work, 2-5 % slower; the supernodes differ), so nested dissection must save
  // 1 - kNestedDissectionWorkRatio of the work, and add no nonzeros (PCG on a kept factor pays
  // nnz(L) per iteration).
  const double amd_work = CalcFactorWork();
  const int amd_nonzeros = nonzeros_in_L();
  AnalyzeOrdering(pattern, CalcNestedDissectionOrdering(pattern, /*blocks_of_three=*/true));
  if (CalcFactorWork() <= kNestedDissectionWorkRatio * amd_work &&
      nonzeros_in_L() <= amd_nonzeros) {
    ordering_ = Ordering::kNestedDissection;
    return;
  }
  AnalyzeOrdering(pattern, amd_order);
}

// Counts, then fills, the entries of C per column, remembering where each value sits in A.
void SparseLdlt::BuildPermutedUpper(const SparseMatrix& pattern) {
  // An upper entry A(r, c), r <= c, lands at (min(i, j), max(i, j)) of C with i = P(r), j = P(c).
  const int* outer = pattern.outerIndexPtr();
  const int* inner = pattern.innerIndexPtr();
  c_start_.assign(n_ + 1, 0);
  for (int c = 0; c < n_; ++c)
    for (int p = outer[c]; p < outer[c + 1]; ++p) {
      const int r = inner[p];
      if (r > c) continue;
      c_start_[std::max(iperm_[r], iperm_[c]) + 1]++;
    }
  for (int j = 0; j < n_; ++j) c_start_[j + 1] += c_start_[j];
  const int nnz_c = c_start_[n_];
  c_row_.assign(nnz_c, 0);
  c_source_.assign(nnz_c, 0);
  std::vector<int> next(c_start_.begin(), c_start_.end() - 1);
  for (int c = 0; c < n_; ++c)
    for (int p = outer[c]; p < outer[c + 1]; ++p) {
      const int r = inner[p];
      if (r > c) continue;
      const int i = iperm_[r], j = iperm_[c];
      const int q = next[std::max(i, j)]++;
      c_row_[q] = std::min(i, j);
      c_source_[q] = p;
    }
}

// Davis' LDL symbolic pass over the columns of C.
void SparseLdlt::CalcEliminationTree() {
  // Row k of L has a nonzero in column i exactly for the nodes on the etree paths from each
  // i' < k with C(i', k) != 0 up to k (Davis 2005, sec. 2). Walk them, mark with flag = k, and
  // count one entry in every column passed; the first walk that reaches a root makes k its parent.
  parent_.assign(n_, -1);
  std::vector<int> flag(n_, -1);
  std::vector<int64_t> count(n_, 0);
  for (int k = 0; k < n_; ++k) {
    flag[k] = k;
    for (int q = c_start_[k]; q < c_start_[k + 1]; ++q) {
      for (int i = c_row_[q]; flag[i] != k; i = parent_[i]) {
        if (parent_[i] == -1) parent_[i] = k;
        count[i]++;
        flag[i] = k;
      }
    }
  }
  col_start_.assign(n_ + 1, 0);
  int64_t total = 0;
  for (int j = 0; j < n_; ++j) {
    total += count[j];
    TAUT_DEMAND(total <= std::numeric_limits<int>::max(),
                "SparseLdlt::Analyze: L would have more than 2^31 nonzeros (n = ", n_, ")");
    col_start_[j + 1] = static_cast<int>(total);
  }
}

// Up-looking numeric phase: row k of L and d_k from column k of C, for k = 0..n-1.
bool SparseLdlt::Factorize(const SparseMatrix& A, ElementLoopRunner* runner) {
  TAUT_DEMAND(analyzed_, "SparseLdlt::Factorize called before Analyze");
  TAUT_DEMAND(A.rows() == n_ && A.cols() == n_ && A.isCompressed() &&
                  A.nonZeros() == static_cast<Eigen::Index>(a_inner_.size()) &&
                  std::equal(a_outer_.begin(), a_outer_.end(), A.outerIndexPtr()),
              "SparseLdlt::Factorize: matrix (", A.rows(), "x", A.cols(), ", ", A.nonZeros(),
              " nonzeros) does not have the analysed pattern (", n_, "x", n_, ", ", a_inner_.size(),
              " nonzeros)");
  TAUT_ASSERT(std::equal(a_inner_.begin(), a_inner_.end(), A.innerIndexPtr()));
  factorized_ = false;
  failed_column_ = -1;
  num_negative_pivots_ = 0;
  const double* a_val = A.valuePtr();
  if (supernodal_) {
    if (!supernodal_factor_.Factorize(a_val, runner)) {
      failed_column_ = perm_[supernodal_factor_.failed_column()];
      num_negative_pivots_ = supernodal_factor_.failed_pivot_negative() ? 1 : 0;
      return false;
    }
    supernodal_factor_.CalcPivots(d_);
    factorized_ = true;
    return true;
  }
  std::fill(flag_.begin(), flag_.end(), -1);
  std::fill(col_fill_.begin(), col_fill_.end(), 0);

  for (int k = 0; k < n_; ++k) {
    // Scatter column k of C into y and push the pattern of row k of L onto the stack, in
    // topological order (descendants before ancestors) at stack_[top..n).
    int top = n_;
    flag_[k] = k;
    for (int q = c_start_[k]; q < c_start_[k + 1]; ++q) {
      int i = c_row_[q];
      y_[i] += a_val[c_source_[q]];
      int len = 0;
      for (; flag_[i] != k; i = parent_[i]) {
        stack_[len++] = i;
        flag_[i] = k;
      }
      while (len > 0) stack_[--top] = stack_[--len];
    }
    // Sparse triangular solve L(0:k,0:k) z = y with l_kj = z_j / d_j, and
    // d_k = a_kk - sum_j l_kj^2 d_j = a_kk - sum_j l_kj z_j.
    double d = y_[k];
    y_[k] = 0.0;
    for (; top < n_; ++top) {
      const int j = stack_[top];
      const double z_j = y_[j];
      y_[j] = 0.0;
      const int end = col_start_[j] + col_fill_[j];
      for (int p = col_start_[j]; p < end; ++p) y_[l_row_[p]] -= l_val_[p] * z_j;
      const double l_kj = z_j * d_inv_[j];
      d -= l_kj * z_j;
      l_row_[end] = k;
      l_val_[end] = l_kj;
      col_fill_[j]++;
    }
    if (d == 0.0 || !std::isfinite(d)) {
      failed_column_ = perm_[k];
      return false;
    }
    if (d < 0.0) num_negative_pivots_++;
    d_[k] = d;
    d_inv_[k] = 1.0 / d;
  }
  factorized_ = true;
  return true;
}

// Checks that a factor exists and the right-hand side fits it.
void SparseLdlt::DemandReadyToSolve(Eigen::Index size) const {
  TAUT_DEMAND(factorized_, "SparseLdlt: solve without a successful Factorize");
  TAUT_DEMAND(size == n_, "SparseLdlt: right-hand side has ", size, " rows, the matrix has ", n_);
}

// One right-hand side through the width-1 kernel.
void SparseLdlt::Solve(Eigen::Ref<VecX> b) const {
  DemandReadyToSolve(b.size());
  if (supernodal_) return SolveSupernodal(b.data(), b.size(), 1);
  SolveBlock<1>(b.data(), b.size());
}

void SparseLdlt::MakeSinglePrecisionCopy() {
  if (supernodal_ && factorized_) supernodal_factor_.MakeSinglePrecisionCopy();
}

void SparseLdlt::SolveSinglePrecision(Eigen::Ref<VecX> b) const {
  DemandReadyToSolve(b.size());
  if (!supernodal_ || !supernodal_factor_.has_single_precision_copy()) return Solve(b);
  double* w = work_.data();
  for (int k = 0; k < n_; ++k) w[k] = b[perm_[k]];
  supernodal_factor_.SolveSinglePrecision(w);
  for (int k = 0; k < n_; ++k) b[perm_[k]] = w[k];
}

// Blocks of 16 columns, then one of 8 and one of 4, then single columns.
void SparseLdlt::SolveColumns(Eigen::Ref<MatX> B) const {
  DemandReadyToSolve(B.rows());
  const Eigen::Index stride = B.outerStride();
  Eigen::Index c = 0;
  const Eigen::Index m = B.cols();
  if (supernodal_) {
    for (; c < m; c += kMaxBlockColumns)
      SolveSupernodal(B.data() + c * stride, stride,
                      static_cast<int>(std::min<Eigen::Index>(kMaxBlockColumns, m - c)));
    return;
  }
  for (; c + kMaxBlockColumns <= m; c += kMaxBlockColumns)
    SolveBlock<kMaxBlockColumns>(B.data() + c * stride, stride);
  if (c + 8 <= m) {
    SolveBlock<8>(B.data() + c * stride, stride);
    c += 8;
  }
  if (c + 4 <= m) {
    SolveBlock<4>(B.data() + c * stride, stride);
    c += 4;
  }
  for (; c < m; ++c) SolveBlock<1>(B.data() + c * stride, stride);
}

// forward: L Z = X in the workspace, column by column of L; zero rows (sparse right-hand sides
// such as columns of J^T) are skipped.
template <int kWidth>
void SparseLdlt::SolveLowerBlock() const {
  using Row = Eigen::Matrix<double, kWidth, 1>;
  double* w = work_.data();
  auto row = [w](int k) { return Eigen::Map<Row>(w + static_cast<size_t>(k) * kWidth); };
  for (int j = 0; j < n_; ++j) {
    const Row x_j = row(j);
    if ((x_j.array() == 0.0).all()) continue;
    for (int p = col_start_[j]; p < col_start_[j + 1]; ++p) row(l_row_[p]) -= l_val_[p] * x_j;
  }
}

// backward: L^T W = Y in the workspace, row j of W = y_j - sum_i L(i, j) w_i over column j.
template <int kWidth>
void SparseLdlt::SolveLowerTransposedBlock() const {
  using Row = Eigen::Matrix<double, kWidth, 1>;
  double* w = work_.data();
  auto row = [w](int k) { return Eigen::Map<Row>(w + static_cast<size_t>(k) * kWidth); };
  for (int j = n_ - 1; j >= 0; --j) {
    Row s = row(j);
    for (int p = col_start_[j]; p < col_start_[j + 1]; ++p) s -= l_val_[p] * row(l_row_[p]);
    row(j) = s;
  }
}

// x = P^T L^-T D^-1 L^-1 P b for kWidth columns at once, through the row-major workspace.
template <int kWidth>
void SparseLdlt::SolveBlock(double* b, Eigen::Index outer_stride) const {
  static_assert(kWidth <= kMaxBlockColumns, "workspace holds kMaxBlockColumns columns");
  double* w = work_.data();
  // gather: X = P B.
  for (int k = 0; k < n_; ++k)
    for (int c = 0; c < kWidth; ++c) w[k * kWidth + c] = b[perm_[k] + c * outer_stride];
  SolveLowerBlock<kWidth>();
  // diagonal: Y = D^-1 Z.
  for (int k = 0; k < n_; ++k)
    for (int c = 0; c < kWidth; ++c) w[k * kWidth + c] *= d_inv_[k];
  SolveLowerTransposedBlock<kWidth>();
  // scatter: B = P^T W.
  for (int k = 0; k < n_; ++k)
    for (int c = 0; c < kWidth; ++c) b[perm_[k] + c * outer_stride] = w[k * kWidth + c];
}

// X = P B into the workspace (row-major, n x width), the supernodal solve, B = P^T X.
void SparseLdlt::SolveSupernodal(double* b, Eigen::Index outer_stride, int width) const {
  static_assert(kMaxBlockColumns <= SupernodalCholesky::kMaxSolveColumns, "solve block width");
  double* w = work_.data();
  for (int k = 0; k < n_; ++k)
    for (int c = 0; c < width; ++c) w[k * width + c] = b[perm_[k] + c * outer_stride];
  supernodal_factor_.Solve(w, width);
  for (int k = 0; k < n_; ++k)
    for (int c = 0; c < width; ++c) b[perm_[k] + c * outer_stride] = w[k * width + c];
}

// Z = D^-1/2 L^-1 P B by blocks of kMaxBlockColumns (the supernodal factor's L is the Cholesky
// factor, D = I there), left in elimination order. The columns go through in the order of their
// first nonzero in elimination order, so the columns of one block share most of their paths.
void SparseLdlt::HalfSolveColumns(const SparseColumns& B, Eigen::Ref<MatX> Z) const {
  DemandReadyToSolve(Z.rows());
  TAUT_DEMAND(num_negative_pivots_ == 0, "SparseLdlt: half solve of an indefinite matrix (",
              num_negative_pivots_, " negative pivots)");
  const int m = B.cols();
  TAUT_DEMAND(Z.cols() == m, "SparseLdlt: half solve of ", m, " sparse columns into ", Z.cols());
  for (int i : B.index)
    TAUT_DEMAND(i >= 0 && i < n_, "SparseLdlt: sparse column entry at row ", i, " of ", n_);
  // Columns ordered by their first nonzero in elimination order, so a block's forward solve
  // starts where its columns do.
  half_order_.resize(m);
  for (int c = 0; c < m; ++c) {
    int first = n_;
    for (int e = B.start[c]; e < B.start[c + 1]; ++e)
      if (B.value[e] != 0.0) first = std::min(first, iperm_[B.index[e]]);
    half_order_[c] = {first, c};
  }
  std::sort(half_order_.begin(), half_order_.end());
  double* w = work_.data();
  for (int c0 = 0; c0 < m; c0 += kMaxBlockColumns) {
    const int width = std::min(kMaxBlockColumns, m - c0);
    // The scalar kernel runs at width 1, 4, 8 or 16 (unused columns zero); the supernodal one at
    // `width`.
    const int w_stride = supernodal_  ? width
                         : width <= 1 ? 1
                         : width <= 4 ? 4
                         : width <= 8 ? 8
                                      : kMaxBlockColumns;
    // w (n x w_stride, row-major) = P B of the block's columns, entries summed in order.
    std::fill(w, w + static_cast<size_t>(n_) * w_stride, 0.0);
    for (int c = 0; c < width; ++c) {
      const int source = half_order_[c0 + c].second;
      for (int e = B.start[source]; e < B.start[source + 1]; ++e)
        w[iperm_[B.index[e]] * w_stride + c] += B.value[e];
    }
    if (supernodal_)
      supernodal_factor_.SolveLower(w, width);
    else if (w_stride == 1)
      SolveLowerBlock<1>();
    else if (w_stride == 4)
      SolveLowerBlock<4>();
    else if (w_stride == 8)
      SolveLowerBlock<8>();
    else
      SolveLowerBlock<kMaxBlockColumns>();
    // Z = D^-1/2 (L^-1 P B), one square root per row for the whole block.
    for (int k = 0; k < n_; ++k) {
      const double d_inv_sqrt = supernodal_ ? 1.0 : std::sqrt(d_inv_[k]);
      for (int c = 0; c < width; ++c)
        Z(k, half_order_[c0 + c].second) = w[k * w_stride + c] * d_inv_sqrt;
    }
  }
}

// x = P^T L^-T D^-1/2 z, the other half: CompleteHalfSolve(HalfSolve(b)) = A^-1 b.
void SparseLdlt::CompleteHalfSolve(Eigen::Ref<VecX> z) const {
  DemandReadyToSolve(z.size());
  double* w = work_.data();
  if (supernodal_) {
    for (int k = 0; k < n_; ++k) w[k] = z[k];
    supernodal_factor_.SolveLowerTransposed(w, 1);
  } else {
    for (int k = 0; k < n_; ++k) w[k] = z[k] * std::sqrt(d_inv_[k]);
    SolveLowerTransposedBlock<1>();
  }
  for (int k = 0; k < n_; ++k) z[perm_[k]] = w[k];
}

double SparseLdlt::CalcFactorWork() const {
  if (!analyzed_) return 0.0;
  double work = 0.0;
  for (int j = 0; j < n_; ++j) {
    const double c = col_start_[j + 1] - col_start_[j];
    work += 0.5 * c * (c + 3.0);
  }
  return work;
}

}  // namespace taut
