#include "constraints/active_set_polish.h"

#include <Eigen/Cholesky>

#include "constraints/lcp_residual.h"

namespace taut {

double PolishActiveSet(const MatX& W, const VecX& q, const std::vector<PgsRow>& rows,
                       Eigen::Ref<VecX> lambda, const PgsSettings& pgs,
                       const ActiveSetPolishSettings& settings, int* sweeps) {
  const int m = static_cast<int>(q.size());
  double residual = internal::CalcLcpResidualUnchecked(W, q, rows, lambda).natural_map;
  for (const PgsRow& row : rows)
    if (row.kind != RowKind::kUnilateral) return residual;
  if (m == 0) return residual;
  std::vector<int> active;
  VecX candidate(m), trial(m);
  // Objective of the unilateral LCP as a bound-constrained QP: f = 1/2 l^T W l + q^T l.
  auto objective = [&](const VecX& l) { return 0.5 * l.dot(W * l) + q.dot(l); };
  double f = objective(lambda);
  for (int round = 0; round < settings.max_rounds && residual > settings.tolerance; ++round) {
    // Free set: positive multipliers, and zero ones whose gradient w pushes them up.
    const VecX w = W * lambda + q;
    active.clear();
    for (int c = 0; c < m; ++c)
      if (lambda[c] > 0.0 || w[c] < 0.0) active.push_back(c);
    if (active.empty()) break;
    const int k = static_cast<int>(active.size());
    MatX W_FF(k, k);
    VecX rhs(k);
    for (int a = 0; a < k; ++a) {
      rhs[a] = -w[active[a]];
      for (int b = 0; b < k; ++b) W_FF(a, b) = W(active[a], active[b]);
      // Each row regularized relative to its own W_cc: rows of one island differ in scale by up to
      // 1e9 (the finger: contact rows in distance units, strain rows of stiff and soft elements),
      // and a shift relative to the largest W_cc swamped the small rows' block.
      W_FF(a, a) += settings.regularization * W(active[a], active[a]);
    }
    // Newton direction on the free set, then a projected backtracking search on f
    // (bound-constrained projected Newton): f never increases, so the refinement cannot diverge.
    const VecX d = W_FF.ldlt().solve(rhs);
    if (!d.allFinite()) break;
    double t = 1.0;
    bool accepted = false;
    for (int halving = 0; halving < 12 && !accepted; ++halving, t *= 0.5) {
      trial = lambda;
      for (int a = 0; a < k; ++a) trial[active[a]] = std::max(0.0, lambda[active[a]] + t * d[a]);
      const double f_trial = objective(trial);
      if (f_trial < f) {
        accepted = true;
        candidate = trial;
        f = f_trial;
      }
    }
    if (!accepted) break;
    if (settings.sweeps_per_round > 0) {
      PgsSettings fix = pgs;
      fix.max_sweeps = settings.sweeps_per_round;
      fix.validate_input = false;  // same problem as the PGS call that came before
      const PgsStats stats = SolvePgs(W, q, rows, candidate, fix);
      if (sweeps != nullptr) *sweeps += stats.sweeps;
      f = objective(candidate);
    }
    lambda = candidate;
    residual = internal::CalcLcpResidualUnchecked(W, q, rows, lambda).natural_map;
  }
  return residual;
}

}  // namespace taut
