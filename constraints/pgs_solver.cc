// Projected Gauss-Seidel sweeps (docs/math.md §5.6).
#include "constraints/pgs_solver.h"

#include <cmath>

namespace taut {
namespace {

// Throws InputError unless every settings field is in its documented range.
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
};

// Value of a skipped row: the point of its feasible set nearest 0 (W_cc ~ 0 means lambda_c
// barely moves w, so any larger value is unjustified).
double CalcSkippedValue(const PgsRow& row) {
  return row.kind == RowKind::kFriction ? 0.0 : ClampToBox(0.0, row.lo, row.hi);
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
  // Prepare: skip threshold relative to the largest diagonal; skipped rows set once.
  const double max_diagonal = W.diagonal().maxCoeff();
  Sweep sweep{W, q, rows, lambda, settings.relaxation, settings.min_diagonal * max_diagonal};
  for (int c = 0; c < m; ++c) {
    if (!sweep.IsSkipped(c)) continue;
    ++stats.skipped_rows;
    lambda[c] = CalcSkippedValue(rows[c]);
  }
  if (settings.w_workspace != nullptr) {
    // Incremental w: one product now, then a column update per changed multiplier.
    VecX& w = *settings.w_workspace;
    w.resize(m);
    w.noalias() = W * lambda;
    w += q;
    sweep.w = &w;
  }
  bool residual_current = false;
  for (int s = 0; s < settings.max_sweeps; ++s) {
    // Sweep: every row in index order; a disk pair at its first row.
    sweep.delta = 0.0;
    for (int c = 0; c < m; ++c) {
      const PgsRow& row = rows[c];
      if (row.kind == RowKind::kFriction && row.cone == FrictionCone::kDisk && row.partner >= 0) {
        if (c < row.partner) sweep.UpdateDiskPair(c, row.partner, row.mu, lambda[row.normal]);
        continue;
      }
      if (sweep.IsSkipped(c)) continue;
      if (row.kind == RowKind::kFriction) {  // box cone or single tangential row
        const double radius = CalcCoulombRadius(row.mu, lambda[row.normal]);
        sweep.UpdateBoxRow(c, -radius, radius);
      } else {
        sweep.UpdateBoxRow(c, row.lo, row.hi);
      }
    }
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
