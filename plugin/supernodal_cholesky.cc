#include "plugin/supernodal_cholesky.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "plugin/dense_kernels.h"

namespace taut {

void SupernodalCholesky::Analyze(int n, const std::vector<int>& c_start,
                                 const std::vector<int>& c_row, const std::vector<int>& c_source,
                                 const std::vector<int>& parent,
                                 const std::vector<int>& l_col_start) {
  n_ = n;
  FindSupernodes(n, parent, l_col_start);
  AmalgamateSupernodes(parent, l_col_start);
  BuildPanelRows(c_start, c_row, parent);
  // Every panel's rows are its columns plus L's pattern below its first column (and the rows a
  // merged child brought).
  for (int s = 0; s < num_supernodes(); ++s)
    TAUT_ASSERT(rows_in(s) >= l_col_start[sn_start_[s] + 1] - l_col_start[sn_start_[s]] + 1);
  BuildScatterMap(c_start, c_row, c_source);
}

// Column j + 1 continues j's supernode when parent(j) = j + 1 and |L(:, j)| = |L(:, j + 1)| + 1:
// then L(:, j) = {j + 1} + L(:, j + 1) (Liu, Ng and Peyton 1993, fundamental supernodes without
// the single-child condition, which only matters for the tree shape, not for the pattern).
void SupernodalCholesky::FindSupernodes(int n, const std::vector<int>& parent,
                                        const std::vector<int>& l_col_start) {
  sn_start_.clear();
  sn_of_.assign(n, 0);
  for (int j = 0; j < n; ++j) {
    const bool continues =
        j > 0 && parent[j - 1] == j &&
        l_col_start[j] - l_col_start[j - 1] == l_col_start[j + 1] - l_col_start[j] + 1;
    if (!continues) sn_start_.push_back(j);
    sn_of_[j] = static_cast<int>(sn_start_.size()) - 1;
  }
  sn_start_.push_back(n);
}

// Relaxed amalgamation (Ashcraft and Grimes 1989; CHOLMOD's default thresholds): a supernode
// merges into the next one, its etree parent, when the merged panel stays small or its stored
// zeros stay a small share: up to 4 columns always, 16 with < 80 %, 48 with < 10 %, any with
// < 5 % zeros. Fewer, wider panels: fewer dense calls and scatters for the same work.
void SupernodalCholesky::AmalgamateSupernodes(const std::vector<int>& parent,
                                              const std::vector<int>& l_col_start) {
  // Stored entries of a w-column panel with m rows (its lower trapezoid).
  auto stored = [](double w, double m) { return w * m - 0.5 * w * (w - 1.0); };
  std::vector<int> merged{0};
  double group_zeros = 0.0;
  int group_rows = 0;  // rows of the current group's panel
  for (int s = 0; s < num_supernodes(); ++s) {
    const int first = sn_start_[s], w = width(s);
    const int m = l_col_start[first + 1] - l_col_start[first] + 1;
    const int group_first = merged.back(), group_width = first - group_first;
    bool merge = false;
    double zeros = 0.0;
    if (group_width > 0 && parent[first - 1] == first) {
      const double cols = group_width + w, rows = group_width + m;
      zeros = stored(cols, rows) - (stored(group_width, group_rows) - group_zeros) - stored(w, m);
      const double share = zeros / stored(cols, rows);
      merge =
          cols <= 4 || (cols <= 16 && share < 0.8) || (cols <= 48 && share < 0.1) || share < 0.05;
    }
    if (merge) {
      group_zeros = zeros;
      group_rows = group_width + m;
    } else {
      if (s > 0) merged.push_back(first);
      group_zeros = 0.0;
      group_rows = m;
    }
  }
  merged.push_back(n_);
  sn_start_ = merged;
  for (int s = 0; s < num_supernodes(); ++s)
    for (int j = sn_start_[s]; j < sn_start_[s + 1]; ++j) sn_of_[j] = s;
}

void SupernodalCholesky::BuildPanelRows(const std::vector<int>& c_start,
                                        const std::vector<int>& c_row,
                                        const std::vector<int>& parent) {
  const int num_sn = num_supernodes();
  // C's strictly upper entries (r, c), r < c, are L's entries (c, r): rows of column r.
  std::vector<int> lower_start(n_ + 1, 0);
  for (int c = 0; c < n_; ++c)
    for (int q = c_start[c]; q < c_start[c + 1]; ++q)
      if (c_row[q] < c) lower_start[c_row[q] + 1]++;
  for (int j = 0; j < n_; ++j) lower_start[j + 1] += lower_start[j];
  std::vector<int> lower_row(lower_start[n_]);
  std::vector<int> fill(lower_start.begin(), lower_start.end() - 1);
  for (int c = 0; c < n_; ++c)
    for (int q = c_start[c]; q < c_start[c + 1]; ++q)
      if (c_row[q] < c) lower_row[fill[c_row[q]]++] = c;

  // Children of each supernode in the supernodal etree.
  std::vector<int> child_head(num_sn, -1), child_next(num_sn, -1);
  for (int s = num_sn - 1; s >= 0; --s) {
    const int p = parent[sn_start_[s + 1] - 1];
    if (p < 0) continue;
    child_next[s] = child_head[sn_of_[p]];
    child_head[sn_of_[p]] = s;
  }

  row_start_.assign(num_sn + 1, 0);
  rows_.clear();
  std::vector<int> mark(n_, -1);
  std::vector<int> below;
  for (int s = 0; s < num_sn; ++s) {
    const int first = sn_start_[s], end = sn_start_[s + 1];
    below.clear();
    auto add = [&](int r) {
      if (r >= end && mark[r] != s) {
        mark[r] = s;
        below.push_back(r);
      }
    };
    for (int j = first; j < end; ++j)
      for (int q = lower_start[j]; q < lower_start[j + 1]; ++q) add(lower_row[q]);
    for (int c = child_head[s]; c != -1; c = child_next[c])
      for (int q = row_start_[c]; q < row_start_[c + 1]; ++q) add(rows_[q]);
    std::sort(below.begin(), below.end());
    for (int j = first; j < end; ++j) rows_.push_back(j);
    rows_.insert(rows_.end(), below.begin(), below.end());
    row_start_[s + 1] = static_cast<int>(rows_.size());
  }
}

void SupernodalCholesky::BuildScatterMap(const std::vector<int>& c_start,
                                         const std::vector<int>& c_row,
                                         const std::vector<int>& c_source) {
  const int num_sn = num_supernodes();
  val_start_.assign(num_sn + 1, 0);
  int64_t total = 0;
  int max_rows = 0, max_width = 0;
  for (int s = 0; s < num_sn; ++s) {
    total += static_cast<int64_t>(rows_in(s)) * width(s);
    TAUT_DEMAND(total <= std::numeric_limits<int>::max(),
                "SupernodalCholesky::Analyze: the panels would hold more than 2^31 values");
    val_start_[s + 1] = static_cast<int>(total);
    max_rows = std::max(max_rows, rows_in(s));
    max_width = std::max(max_width, width(s));
  }
  values_.assign(static_cast<size_t>(total), 0.0);

  // Entry (r, c) of C, r <= c, is L's (c, r): column r's panel, at row c's position there.
  std::vector<int> pos(n_, -1);
  entry_dest_.assign(c_source.size(), 0);
  entry_source_.assign(c_source.begin(), c_source.end());
  std::vector<int> row_pos_of_entry(c_source.size());
  // Positions are relative to the panel of the entry's column r; fill them panel by panel.
  std::vector<int> entries_start(num_sn + 1, 0);
  for (int c = 0; c < n_; ++c)
    for (int q = c_start[c]; q < c_start[c + 1]; ++q) entries_start[sn_of_[c_row[q]] + 1]++;
  for (int s = 0; s < num_sn; ++s) entries_start[s + 1] += entries_start[s];
  std::vector<int> by_panel(c_source.size());
  std::vector<int> next_slot(entries_start.begin(), entries_start.end() - 1);
  for (int c = 0; c < n_; ++c)
    for (int q = c_start[c]; q < c_start[c + 1]; ++q) by_panel[next_slot[sn_of_[c_row[q]]]++] = q;
  std::vector<int> col_of(c_source.size());
  for (int c = 0; c < n_; ++c)
    for (int q = c_start[c]; q < c_start[c + 1]; ++q) col_of[q] = c;
  for (int s = 0; s < num_sn; ++s) {
    for (int k = 0; k < rows_in(s); ++k) pos[rows_[row_start_[s] + k]] = k;
    for (int i = entries_start[s]; i < entries_start[s + 1]; ++i) {
      const int q = by_panel[i];
      const int r = c_row[q], c = col_of[q];
      TAUT_ASSERT(pos[c] >= 0);
      entry_dest_[q] = val_start_[s] + (r - sn_start_[s]) * rows_in(s) + pos[c];
    }
    for (int k = 0; k < rows_in(s); ++k) pos[rows_[row_start_[s] + k]] = -1;
  }

  head_.assign(num_sn, -1);
  next_.assign(num_sn, -1);
  next_row_.assign(num_sn, 0);
  FindTwoWaySplit();
  for (int g = 0; g < (has_split_ ? 2 : 1); ++g) {
    workspaces_[g].map.assign(n_, 0);
    workspaces_[g].update.assign(static_cast<size_t>(max_rows) * max_width, 0.0);
  }
  solve_work_.assign(static_cast<size_t>(max_rows) * kMaxSolveColumns, 0.0);
}

void SupernodalCholesky::FindTwoWaySplit() {
  const int num_sn = num_supernodes();
  has_split_ = false;
  split_work_ = {0.0, 0.0, 0.0};
  group_nodes_[0].clear();
  group_nodes_[1].clear();
  top_nodes_.clear();
  group_of_.assign(num_sn, 2);
  // Supernodal etree (a panel's parent owns its first row below the diagonal block) and the work
  // of each subtree: w^3 / 3 for the diagonal block, w^2 b for the rows below, w b^2 / 2 for the
  // updates it sends (b = rows below).
  std::vector<int> child_head(num_sn, -1), child_next(num_sn, -1), roots;
  std::vector<double> subtree_work(num_sn, 0.0);
  double total = 0.0;
  for (int s = 0; s < num_sn; ++s) {
    const double w = width(s), b = rows_in(s) - width(s);
    const double own = w * w * w / 3.0 + w * w * b + 0.5 * w * b * b;
    subtree_work[s] += own;
    total += own;
    if (rows_in(s) > width(s)) {
      const int p = sn_of_[rows_[row_start_[s] + width(s)]];
      subtree_work[p] += subtree_work[s];  // p > s: children come first
      child_next[s] = child_head[p];
      child_head[p] = s;
    } else {
      roots.push_back(s);
    }
  }
  if (total < kMinSplitWork) return;
  // A frontier of disjoint subtrees, in two groups by largest-first into the lighter; its
  // estimated time is that of the heavier group plus the supernodes above. From the roots, the
  // heaviest subtree of the frontier is replaced by its children (its own supernode joins those
  // above) while that lowers the estimate, up to kMaxSplitRefinements times.
  auto assign = [&](std::vector<int>& frontier, std::array<double, 2>& work) {
    std::sort(frontier.begin(), frontier.end(), [&](int a, int b) {
      return subtree_work[a] > subtree_work[b] || (subtree_work[a] == subtree_work[b] && a < b);
    });
    work = {0.0, 0.0};
    for (const int s : frontier) work[work[1] < work[0] ? 1 : 0] += subtree_work[s];
    return std::max(work[0], work[1]) + (total - work[0] - work[1]);
  };
  std::vector<int> frontier = roots, best_frontier;
  std::array<double, 2> work{}, best_work{};
  double best_time = total;
  for (int refinement = 0; refinement <= kMaxSplitRefinements && !frontier.empty(); ++refinement) {
    const double time = assign(frontier, work);
    if (frontier.size() >= 2 && time < best_time) {
      best_time = time;
      best_frontier = frontier;
      best_work = work;
    }
    const int heaviest = frontier.front();
    if (child_head[heaviest] == -1) break;
    frontier.erase(frontier.begin());
    for (int c = child_head[heaviest]; c != -1; c = child_next[c]) frontier.push_back(c);
  }
  if (best_frontier.empty() || std::min(best_work[0], best_work[1]) < kMinGroupShare * total)
    return;
  work = {0.0, 0.0};
  std::vector<int> stack;
  for (const int branch : best_frontier) {
    const int g = work[1] < work[0] ? 1 : 0;
    work[g] += subtree_work[branch];
    stack.assign(1, branch);
    while (!stack.empty()) {
      const int s = stack.back();
      stack.pop_back();
      group_of_[s] = g;
      for (int c = child_head[s]; c != -1; c = child_next[c]) stack.push_back(c);
    }
  }
  for (int s = 0; s < num_sn; ++s)
    (group_of_[s] == 2 ? top_nodes_ : group_nodes_[group_of_[s]]).push_back(s);
  split_work_ = {work[0], work[1], total - work[0] - work[1]};
  has_split_ = true;
}

bool SupernodalCholesky::Factorize(const double* a_val, ElementLoopRunner* runner) {
  failed_column_ = -1;
  failed_pivot_negative_ = false;
  single_current_ = false;
  std::fill(values_.begin(), values_.end(), 0.0);
  for (size_t q = 0; q < entry_dest_.size(); ++q)
    values_[entry_dest_[q]] += a_val[entry_source_[q]];
  std::fill(head_.begin(), head_.end(), -1);
  FailedPivot failed;
  const bool ok = has_split_ && runner != nullptr && runner->num_loop_threads() >= 2
                      ? FactorOnTwoThreads(*runner, failed)
                      : FactorSerially(workspaces_[0], failed);
  if (!ok) {
    failed_column_ = failed.column;
    failed_pivot_negative_ = failed.negative;
  }
  return ok;
}

template <typename Link>
bool SupernodalCholesky::FactorSupernode(int t, Workspace& ws, Link& link, FailedPivot& failed) {
  const int* rows_t = rows_.data() + row_start_[t];
  for (int k = 0; k < rows_in(t); ++k) ws.map[rows_t[k]] = k;
  // Step 2: every descendant whose next unconsumed row is one of t's columns.
  for (int d = head_[t], after = 0; d != -1; d = after) {
    after = next_[d];
    const int* rows_d = rows_.data() + row_start_[d];
    const int k1 = next_row_[d];
    int k2 = k1;
    while (k2 < rows_in(d) && rows_d[k2] < sn_start_[t + 1]) ++k2;
    SubtractUpdate(d, k1, k2, t, ws);
    next_row_[d] = k2;
    if (k2 < rows_in(d)) link(d, sn_of_[rows_d[k2]]);
  }
  if (!FactorPanel(t, failed)) return false;
  if (rows_in(t) > width(t)) {
    next_row_[t] = width(t);
    link(t, sn_of_[rows_t[width(t)]]);
  }
  return true;
}

bool SupernodalCholesky::FactorSerially(Workspace& ws, FailedPivot& failed) {
  auto link = [this](int d, int p) { LinkWaiting(d, p); };
  for (int t = 0; t < num_supernodes(); ++t)
    if (!FactorSupernode(t, ws, link, failed)) return false;
  return true;
}

// The serial order of the links into each list is that of the supernode t being factored when
// they were made (ascending t): a thread links into its own group's lists directly (only its own
// supernodes link there), and the links into the lists above the groups are applied after both
// threads, in ascending t, interleaved with the supernodes above by index. So every list, and
// with it the order of every supernode's updates, is the serial one.
bool SupernodalCholesky::FactorOnTwoThreads(ElementLoopRunner& runner, FailedPivot& failed) {
  constexpr int kNone = std::numeric_limits<int>::max();
  std::array<FailedPivot, 2> group_failed;
  std::array<int, 2> failed_at{kNone, kNone};
  auto factor_group = [&](int g) {
    deferred_[g].clear();
    for (const int t : group_nodes_[g]) {
      auto link = [&](int d, int p) {
        if (group_of_[p] == g) {
          LinkWaiting(d, p);
        } else {
          deferred_[g].push_back({t, d, p});
        }
      };
      if (!FactorSupernode(t, workspaces_[g], link, group_failed[g])) {
        failed_at[g] = t;
        return;
      }
    }
  };
  runner.RunChunks(2, factor_group);
  // The links of both threads in ascending t, each applied before the first supernode above
  // the groups that comes after its t (links only go to later supernodes).
  size_t i = 0, j = 0;
  const std::vector<DeferredLink>& a = deferred_[0];
  const std::vector<DeferredLink>& b = deferred_[1];
  auto apply_links_before = [&](int u) {
    while ((i < a.size() && a[i].t < u) || (j < b.size() && b[j].t < u)) {
      const DeferredLink& next =
          j == b.size() || (i < a.size() && a[i].t < b[j].t) ? a[i++] : b[j++];
      LinkWaiting(next.d, next.p);
    }
  };
  auto link = [this](int d, int p) { LinkWaiting(d, p); };
  // After a failure in a group the serial loop would still have factored (and may have failed at)
  // the supernodes above the groups that come before it; none after it.
  const int group_failure = std::min(failed_at[0], failed_at[1]);
  for (const int t : top_nodes_) {
    if (t > group_failure) break;
    apply_links_before(t);
    if (!FactorSupernode(t, workspaces_[0], link, failed)) return false;
  }
  if (group_failure == kNone) return true;
  failed = group_failed[failed_at[0] < failed_at[1] ? 0 : 1];
  return false;
}

// Panel_t(rows_d[i], rows_d[j]) -= sum_c L_d(i, c) L_d(j, c) for k1 <= j < k2, i >= j.
void SupernodalCholesky::SubtractUpdate(int d, int k1, int k2, int t, Workspace& ws) {
  const double* l_d = values_.data() + val_start_[d];
  const int n1 = k2 - k1, n2 = rows_in(d) - k1;
  ActiveDenseKernels().multiply_by_transposed(l_d + k1, rows_in(d), l_d + k1, rows_in(d), n2, n1,
                                              width(d), ws.update.data(), n2);
  const Panel update(ws.update.data(), n2, n1);
  const int* rows_d = rows_.data() + row_start_[d];
  Panel l_t = panel(t);
  const int first_t = sn_start_[t];
  for (int j = 0; j < n1; ++j) {
    double* col = l_t.col(rows_d[k1 + j] - first_t).data();
    for (int i = j; i < n2; ++i) col[ws.map[rows_d[k1 + i]]] -= update(i, j);
  }
}

// L_tt L_tt^T = diagonal block (blocked in-place Cholesky); L_below = below L_tt^-T.
bool SupernodalCholesky::FactorPanel(int t, FailedPivot& failed) {
  const DenseKernels& kernels = ActiveDenseKernels();
  double* l_t = values_.data() + val_start_[t];
  const int w = width(t), m = rows_in(t);
  const int failed_at = kernels.cholesky_lower(l_t, m, w);
  if (failed_at >= 0) {
    failed.column = sn_start_[t] + failed_at;
    failed.negative = true;
    return false;
  }
  for (int k = 0; k < w; ++k)
    if (!std::isfinite(l_t[k * m + k])) {
      failed.column = sn_start_[t] + k;
      return false;
    }
  if (m > w) kernels.solve_right_lower_transposed(l_t, m, w, l_t + w, m, m - w);
  return true;
}

// Forward L Z = Y, one supernode's dense blocks at a time (Y row-major, width_b columns).
void SupernodalCholesky::SolveLower(double* y_data, int width_b) const {
  TAUT_ASSERT(width_b <= kMaxSolveColumns);
  const DenseKernels& kernels = ActiveDenseKernels();
  double* t = solve_work_.data();
  const int num_sn = num_supernodes();
  for (int s = 0; s < num_sn; ++s) {
    const int w = width(s), below = rows_in(s) - w;
    double* y_s = y_data + static_cast<std::ptrdiff_t>(sn_start_[s]) * width_b;
    // Zero rows stay zero (sparse right-hand sides such as columns of J^T).
    if (std::all_of(y_s, y_s + w * width_b, [](double v) { return v == 0.0; })) continue;
    kernels.forward_supernode(values_.data() + val_start_[s], rows_in(s), w, below, y_s, width_b,
                              t);
    const int* rows_below = rows_.data() + row_start_[s] + w;
    for (int k = 0; k < below; ++k) {
      double* y_row = y_data + static_cast<std::ptrdiff_t>(rows_below[k]) * width_b;
      for (int c = 0; c < width_b; ++c) y_row[c] -= t[k * width_b + c];
    }
  }
}

// Backward L^T X = Z, supernodes in reverse order.
void SupernodalCholesky::SolveLowerTransposed(double* y_data, int width_b) const {
  TAUT_ASSERT(width_b <= kMaxSolveColumns);
  const DenseKernels& kernels = ActiveDenseKernels();
  double* t = solve_work_.data();
  for (int s = num_supernodes() - 1; s >= 0; --s) {
    const int w = width(s), below = rows_in(s) - w;
    const int* rows_below = rows_.data() + row_start_[s] + w;
    for (int k = 0; k < below; ++k) {
      const double* y_row = y_data + static_cast<std::ptrdiff_t>(rows_below[k]) * width_b;
      std::copy(y_row, y_row + width_b, t + k * width_b);
    }
    double* y_s = y_data + static_cast<std::ptrdiff_t>(sn_start_[s]) * width_b;
    kernels.backward_supernode(values_.data() + val_start_[s], rows_in(s), w, below, y_s, width_b,
                               t);
  }
}

// C^-1 = L^-T L^-1.
void SupernodalCholesky::Solve(double* y_data, int width_b) const {
  SolveLower(y_data, width_b);
  SolveLowerTransposed(y_data, width_b);
}

void SupernodalCholesky::MakeSinglePrecisionCopy() {
  if (single_current_) return;
  values_single_.resize(values_.size());
  for (size_t k = 0; k < values_.size(); ++k) values_single_[k] = static_cast<float>(values_[k]);
  single_current_ = true;
}

// (L_f L_f^T)^-1 y by panels: each gathers its rows of y into a dense u, solves there
// (DenseKernels::forward_panel_single / backward_panel_single) and scatters back.
void SupernodalCholesky::SolveSinglePrecision(double* y) const {
  TAUT_ASSERT(single_current_);
  const DenseKernels& kernels = ActiveDenseKernels();
  double* u = solve_work_.data();
  const int num_sn = num_supernodes();
  for (int s = 0; s < num_sn; ++s) {
    const int w = width(s), m = rows_in(s);
    const int* rows_s = rows_.data() + row_start_[s];  // the panel's columns, then rows below
    bool zero = true;
    for (int k = 0; k < w; ++k) zero = zero && y[rows_s[k]] == 0.0;
    if (zero) continue;  // zero rows stay zero
    for (int k = 0; k < m; ++k) u[k] = k < w ? y[rows_s[k]] : 0.0;
    kernels.forward_panel_single(values_single_.data() + val_start_[s], m, w, u);
    for (int k = 0; k < w; ++k) y[rows_s[k]] = u[k];
    for (int k = w; k < m; ++k) y[rows_s[k]] += u[k];
  }
  for (int s = num_sn - 1; s >= 0; --s) {
    const int w = width(s), m = rows_in(s);
    const int* rows_s = rows_.data() + row_start_[s];
    for (int k = 0; k < m; ++k) u[k] = y[rows_s[k]];
    kernels.backward_panel_single(values_single_.data() + val_start_[s], m, w, u);
    for (int k = 0; k < w; ++k) y[rows_s[k]] = u[k];
  }
}

void SupernodalCholesky::CalcPivots(std::vector<double>& d) const {
  d.resize(n_);
  for (int s = 0; s < num_supernodes(); ++s) {
    const ConstPanel l_s = read_panel(s);
    for (int k = 0; k < width(s); ++k) d[sn_start_[s] + k] = l_s(k, k) * l_s(k, k);
  }
}

}  // namespace taut
