// Projected Gauss-Seidel sweeps (docs/math.md §5.6).
#include "constraints/pgs_solver.h"

#include <cmath>

namespace taut {

void ValidatePgsSettings(const PgsSettings& s) {
  TAUT_DEMAND(s.max_sweeps >= 0, "PgsSettings: max_sweeps = ", s.max_sweeps, " must be >= 0");
  TAUT_DEMAND(s.tolerance >= 0.0 && s.residual_tolerance >= 0.0,
              "PgsSettings: tolerance = ", s.tolerance,
              " and residual_tolerance = ", s.residual_tolerance, " must be >= 0");
  TAUT_DEMAND(s.relaxation > 0.0 && s.relaxation < 2.0, "PgsSettings: relaxation = ", s.relaxation,
              " must be in (0, 2)");
  TAUT_DEMAND(s.min_diagonal >= 0.0 && s.min_diagonal < 1.0,
              "PgsSettings: min_diagonal = ", s.min_diagonal, " must be in [0, 1)");
}

namespace {

// The sweep state shared by the row kernels: problem, iterate, skip threshold, sweep maximum.
struct Sweep {
  const MatX& W;
  const VecX& q;
  const std::vector<PgsRow>& rows;
  Eigen::Ref<VecX>& lambda;
  double omega;
  double threshold;   // rows with W_cc <= threshold are skipped
  VecX* w = nullptr;  // optional w = W lambda + q kept current: O(m) per changed row, O(1) else
  double delta = 0.0;

  // Whether row c is skipped for a too small diagonal.
  bool IsSkipped(int c) const { return !(W(c, c) > threshold); }
  // w_c = q_c + (W lambda)_c, column c by symmetry.
  double CalcW(int c) const { return w != nullptr ? (*w)[c] : q[c] + W.col(c).dot(lambda); }
  // Stores lambda_c and records W_cc |Delta lambda_c|.
  void Set(int c, double value) {
    const double change = value - lambda[c];
    delta = std::max(delta, W(c, c) * std::abs(change));
    if (w != nullptr && change != 0.0) w->noalias() += W.col(c) * change;
    lambda[c] = value;
  }
  // Scalar update of row c on [lo, hi].
  void UpdateBoxRow(int c, double lo, double hi) {
    Set(c, CalcBoxRowUpdate(lambda[c], CalcW(c), W(c, c), lo, hi, omega));
  }
  // Block update of disk pair (c, p): exact 2x2 solve, SOR, projection back onto the disk.
  void UpdateDiskPair(int c, int p, double mu, double lambda_n) {
    const double radius = CalcCoulombRadius(mu, lambda_n);
    const bool skip_c = IsSkipped(c), skip_p = IsSkipped(p);
    if (skip_c && skip_p) return;
    if (skip_c || skip_p) {  // the other row is held at 0: the disk becomes an interval
      const int k = skip_c ? p : c;
      UpdateBoxRow(k, -radius, radius);
      return;
    }
    const Eigen::Vector2d w_t(CalcW(c), CalcW(p));
    const Eigen::Vector2d lambda_t(lambda[c], lambda[p]);
    Eigen::Matrix2d B;
    B << W(c, c), W(c, p), W(p, c), W(p, p);
    const Eigen::Vector2d g = w_t - B * lambda_t;  // pair velocity without its own impulse
    const Eigen::Vector2d exact = SolveCoulombDiskBlock(B, g, radius);
    const Eigen::Vector2d relaxed = lambda_t + omega * (exact - lambda_t);
    const Eigen::Vector2d next = ProjectOnCoulombDisk(relaxed[0], relaxed[1], mu, lambda_n);
    Set(c, next[0]);
    Set(p, next[1]);
  }
  // One sweep: every row in index order, a disk pair at its first row; delta = the sweep's
  // largest W_cc |Delta lambda_c|.
  void SweepRows() {
    delta = 0.0;
    for (int c = 0; c < static_cast<int>(rows.size()); ++c) {
      const PgsRow& row = rows[c];
      if (row.kind == RowKind::kFriction && row.cone == FrictionCone::kDisk && row.partner >= 0) {
        if (c < row.partner) UpdateDiskPair(c, row.partner, row.mu, lambda[row.normal]);
        continue;
      }
      if (IsSkipped(c)) continue;
      if (row.kind == RowKind::kFriction) {  // box cone or single tangential row
        const double radius = CalcCoulombRadius(row.mu, lambda[row.normal]);
        UpdateBoxRow(c, -radius, radius);
      } else {
        UpdateBoxRow(c, row.lo, row.hi);
      }
    }
  }
};

// Value of a skipped row: the point of its feasible set nearest 0 (W_cc ~ 0 means lambda_c
// barely moves w, so any larger value is unjustified).
double CalcSkippedValue(const PgsRow& row) {
  return row.kind == RowKind::kFriction ? 0.0 : ClampToBox(0.0, row.lo, row.hi);
}

// Stage: skipped rows set once to their value; returns their count.
int SetSkippedRows(Sweep& sweep) {
  int skipped = 0;
  for (int c = 0; c < static_cast<int>(sweep.rows.size()); ++c) {
    if (!sweep.IsSkipped(c)) continue;
    ++skipped;
    sweep.lambda[c] = CalcSkippedValue(sweep.rows[c]);
  }
  return skipped;
}

// Stage: incremental w = W lambda + q, one product now, then a column update per changed
// multiplier.
VecX& InitIncrementalW(const Sweep& sweep, VecX& w) {
  w.resize(sweep.q.size());
  w.noalias() = sweep.W * sweep.lambda;
  w += sweep.q;
  return w;
}

}  // namespace

PgsStats SolvePgs(const MatX& W, const VecX& q, const std::vector<PgsRow>& rows,
                  Eigen::Ref<VecX> lambda, const PgsSettings& settings) {
  ValidatePgsSettings(settings);
  if (settings.validate_input) ValidateLcpProblem(W, q, rows, lambda);
  PgsStats stats;
  const int m = static_cast<int>(rows.size());
  if (m == 0) {
    stats.converged = true;
    return stats;
  }
  // Prepare: skip threshold relative to the largest diagonal.
  Sweep sweep{
      W, q, rows, lambda, settings.relaxation, settings.min_diagonal * W.diagonal().maxCoeff()};
  stats.skipped_rows = SetSkippedRows(sweep);
  if (settings.w_workspace != nullptr) sweep.w = &InitIncrementalW(sweep, *settings.w_workspace);
  bool residual_current = false;
  for (int s = 0; s < settings.max_sweeps; ++s) {
    sweep.SweepRows();
    // Stop test: velocity-scaled change, then (optionally) the natural-map residual.
    stats.sweeps = s + 1;
    stats.final_delta = sweep.delta;
    residual_current = false;
    if (sweep.delta <= settings.tolerance) {
      stats.converged = true;
      break;
    }
    if (settings.residual_tolerance > 0.0) {
      stats.residual = internal::CalcLcpResidualUnchecked(W, q, rows, lambda).natural_map;
      residual_current = true;
      if (stats.residual <= settings.residual_tolerance) {
        stats.converged = true;
        break;
      }
    }
  }
  if (!residual_current) {
    stats.residual = internal::CalcLcpResidualUnchecked(W, q, rows, lambda).natural_map;
  }
  if (!std::isfinite(stats.residual)) {
    throw SimulationError(internal::Concat("SolvePgs: non-finite residual after ", stats.sweeps,
                                           " sweeps (", m, " rows)"));
  }
  return stats;
}

}  // namespace taut
