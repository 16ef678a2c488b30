// Supernodal left-looking Cholesky kernel for SparseLdlt's large matrices.
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

#include "plugin/common.h"
#include "plugin/element_loop_runner.h"

namespace taut {

// C = L L^T of a symmetric positive definite matrix C given in SparseLdlt's permuted form (the
// upper triangle of P A P^T by columns, its values read from A's value array), computed by
// supernodes: runs of columns of L with one shared row pattern, each stored as a dense column-major
// panel (its rows: the supernode's own columns, then the rows below them). Per supernode t
// (left-looking, the scheme of CHOLMOD's supernodal factor; Ng and Peyton 1993):
//   1. gather A's entries of t's columns into its panel,
//   2. subtract L_d(rows of t's panel, :) L_d(t's columns, :)^T of every earlier supernode d whose
//      rows reach t's columns (one dense product each),
//   3. L_tt = chol(diagonal block), L_rest = panel_rest L_tt^-T (dense kernels).
// The dense kernels run at BLAS-3 speed where the up-looking scalar algorithm touches one entry
// at a time, so large 3D bodies (fronts of hundreds of columns) factor several times faster.
//
// Only SPD matrices: Factorize stops at the first pivot that is not positive and finite (an
// indefinite or singular C), where the up-looking LDL^T would go on with negative pivots.
// Factorize and the solves may allocate inside Eigen's dense products for large panels.
class SupernodalCholesky {
 public:
  // Symbolic phase on C's pattern: supernodes from the elimination tree and the column counts
  // of L, the row pattern of every panel, where each entry of A lands in the panels, workspaces.
  // c_start/c_row: CSC of C's upper triangle; c_source: index into A's values of each entry;
  // parent: etree of C (-1 at roots); l_col_start: column starts of L's strictly lower part.
  void Analyze(int n, const std::vector<int>& c_start, const std::vector<int>& c_row,
               const std::vector<int>& c_source, const std::vector<int>& parent,
               const std::vector<int>& l_col_start);

  // Numeric phase with A's values (the pattern Analyze saw). Returns false when a pivot is not
  // positive and finite; failed_column() then names the permuted column (-1 otherwise) and
  // failed_pivot_negative() whether that pivot was negative. With a runner of two or more threads
  // and a split from Analyze (has_two_way_split), the two groups of subtrees factor on two
  // threads, then the supernodes above them: the same operations in the same order per supernode,
  // so L is bitwise that of one thread.
  bool Factorize(const double* a_val, ElementLoopRunner* runner = nullptr);

  // Solves C X = Y in place for a row-major (n x width) block Y (permuted order).
  void Solve(double* y, int width) const;
  // Its halves: L Z = Y (rows of Y that are zero on a whole supernode are skipped, so sparse
  // right-hand sides touch only their elimination-tree paths), then L^T X = Z.
  void SolveLower(double* y, int width) const;
  void SolveLowerTransposed(double* y, int width) const;

  // A single-precision copy of L (made after Factorize) and the solve C X = Y for one column
  // through it, in double arithmetic: an exact solve with the SPD matrix L_f L_f^T, L_f = fl32(L),
  // that reads half the bytes of Solve. For preconditioning, where the factor is an earlier A's
  // and a 1e-7 relative change of L is far below that difference. Solve needs the copy made since
  // the last Factorize.
  void MakeSinglePrecisionCopy();
  bool has_single_precision_copy() const { return single_current_; }
  void SolveSinglePrecision(double* y) const;

  // Pivots of the equivalent LDL^T: D_jj = L_jj^2 (valid after a successful Factorize).
  void CalcPivots(std::vector<double>& d) const;

  int num_supernodes() const { return static_cast<int>(sn_start_.size()) - 1; }
  // True when Analyze found two groups of independent subtrees worth factoring in parallel.
  bool has_two_way_split() const { return has_split_; }
  // Estimated factor work (multiply-adds) of the two groups and of the supernodes above them.
  const std::array<double, 3>& split_work() const { return split_work_; }

  // Factor work from which Analyze looks for a two-way split, and the least share of it each
  // group must carry (measured on 2 cores: below them the threads' hand-over costs more than the
  // split saves).
  static constexpr double kMinSplitWork = 5e6;
  static constexpr double kMinGroupShare = 0.2;
  static constexpr int kMaxSplitRefinements = 32;
  int failed_column() const { return failed_column_; }
  bool failed_pivot_negative() const { return failed_pivot_negative_; }

  // Widest right-hand-side block one pass of Solve carries.
  static constexpr int kMaxSolveColumns = 16;

 private:
  using Panel = Eigen::Map<Eigen::MatrixXd>;
  using ConstPanel = Eigen::Map<const Eigen::MatrixXd>;

  // Partition of the columns into fundamental supernodes (column j + 1 joins j's supernode when
  // it is j's etree parent and L(:, j) = {j + 1} + L(:, j + 1)).
  void FindSupernodes(int n, const std::vector<int>& parent, const std::vector<int>& l_col_start);
  // Merges small supernodes into their parents where few stored zeros result.
  void AmalgamateSupernodes(const std::vector<int>& parent, const std::vector<int>& l_col_start);
  // Row pattern of each panel: its columns, then the union of C's entries below them and the
  // rows of its child supernodes (the etree's row-subtree property).
  void BuildPanelRows(const std::vector<int>& c_start, const std::vector<int>& c_row,
                      const std::vector<int>& parent);
  // Where each entry of C lands in the panel storage, and the size of every workspace.
  void BuildScatterMap(const std::vector<int>& c_start, const std::vector<int>& c_row,
                       const std::vector<int>& c_source);
  // Groups of subtrees for two threads: disjoint subtrees in two groups of about equal work
  // (largest first into the lighter group), found by splitting the heaviest subtree from the
  // roots down while the estimated time falls; the supernodes above them (ancestors of the
  // groups) stay on one thread after them.
  void FindTwoWaySplit();

  // A thread's scratch for steps 2-3: relative row positions in the current panel (n) and the
  // update product (max rows x max width).
  struct Workspace {
    std::vector<int> map;
    std::vector<double> update;
  };
  // A pivot that was not positive and finite.
  struct FailedPivot {
    int column = -1;
    bool negative = false;
  };
  // d joins the list of descendants waiting for supernode p while supernode t is factored (a
  // link into a list above the groups, applied after both threads in the order of t).
  struct DeferredLink {
    int t, d, p;
  };
  // Puts descendant d first on supernode p's list of waiting descendants.
  void LinkWaiting(int d, int p) {
    next_[d] = head_[p];
    head_[p] = d;
  }
  // Steps 2 and 3 for supernode t; link(d, p) puts d on p's list of waiting descendants.
  template <typename Link>
  bool FactorSupernode(int t, Workspace& ws, Link& link, FailedPivot& failed);
  bool FactorSerially(Workspace& ws, FailedPivot& failed);
  bool FactorOnTwoThreads(ElementLoopRunner& runner, FailedPivot& failed);
  // Step 2 for one descendant d of t: rows [k1, m_d) of d's panel against rows [k1, k2).
  void SubtractUpdate(int d, int k1, int k2, int t, Workspace& ws);
  // Step 3: dense Cholesky of t's diagonal block and the triangular solve below it (steps 2-3
  // and the solves run on the CPU's dense kernel set, plugin/dense_kernels.h).
  bool FactorPanel(int t, FailedPivot& failed);

  Panel panel(int s) { return Panel(values_.data() + val_start_[s], rows_in(s), width(s)); }
  ConstPanel read_panel(int s) const {
    return ConstPanel(values_.data() + val_start_[s], rows_in(s), width(s));
  }
  int width(int s) const { return sn_start_[s + 1] - sn_start_[s]; }
  int rows_in(int s) const { return row_start_[s + 1] - row_start_[s]; }

  int n_ = 0;
  std::vector<int> sn_start_;         // (S + 1) first column of each supernode
  std::vector<int> sn_of_;            // (n) supernode of each column
  std::vector<int> row_start_;        // (S + 1) start of each panel's rows in rows_
  std::vector<int> rows_;             // row indices of all panels, ascending within one
  std::vector<int> val_start_;        // (S + 1) start of each panel in values_
  std::vector<double> values_;        // panels, column-major, leading dimension rows_in(s)
  std::vector<float> values_single_;  // fl32(values_) once MakeSinglePrecisionCopy ran
  bool single_current_ = false;       // values_single_ holds the last Factorize's L

  // A's entries: values_[entry_dest_[q]] += a_val[entry_source_[q]].
  std::vector<int> entry_dest_;
  std::vector<int> entry_source_;

  // Factorize workspace: relative row positions in the current panel, the linked lists of
  // descendants waiting for each supernode, each descendant's next row, the update product.
  std::array<Workspace, 2> workspaces_;  // [0]: one thread and the top; [1]: the second thread
  std::vector<int> head_;                // (S) first descendant waiting for supernode t, -1 if none
  std::vector<int> next_;                // (S) next descendant in the same list
  std::vector<int> next_row_;            // (S) index in d's rows of its first row not yet consumed

  // The two-way split (FindTwoWaySplit): each group's supernodes ascending, the rest ascending,
  // the group of every supernode (0, 1; 2 above the groups), links deferred by each thread.
  bool has_split_ = false;
  std::array<double, 3> split_work_{};
  std::array<std::vector<int>, 2> group_nodes_;
  std::vector<int> top_nodes_;
  std::vector<int> group_of_;
  std::array<std::vector<DeferredLink>, 2> deferred_;
  mutable std::vector<double> solve_work_;  // (max rows x kMaxSolveColumns)

  int failed_column_ = -1;
  bool failed_pivot_negative_ = false;
};

}  // namespace taut
