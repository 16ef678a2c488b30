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
  const double reg = settings.regularization * W.diagonal().maxCoeff();
  std::vector<int> active;
  for (int round = 0; round < settings.max_rounds && residual > settings.tolerance; ++round) {
    // Active set from the iterate: positive multipliers and violated rows.
    const VecX w = W * lambda + q;
    active.clear();
    for (int c = 0; c < m; ++c)
      if (lambda[c] > 0.0 || w[c] < 0.0) active.push_back(c);
    if (active.empty()) break;
    const int k = static_cast<int>(active.size());
    MatX W_AA(k, k);
    VecX rhs(k);
    for (int a = 0; a < k; ++a) {
      rhs[a] = -q[active[a]];
      for (int b = 0; b < k; ++b) W_AA(a, b) = W(active[a], active[b]);
      W_AA(a, a) += reg;
    }
    // Direct solve on the active rows; the rest are inactive.
    const VecX lambda_A = W_AA.ldlt().solve(rhs);
    if (!lambda_A.allFinite()) break;
    VecX candidate = VecX::Zero(m);
    for (int a = 0; a < k; ++a) candidate[active[a]] = std::max(0.0, lambda_A[a]);
    PgsSettings fix = pgs;
    fix.max_sweeps = settings.sweeps_per_round;
    const PgsStats stats = SolvePgs(W, q, rows, candidate, fix);
    if (sweeps != nullptr) *sweeps += stats.sweeps;
    const double candidate_residual =
        internal::CalcLcpResidualUnchecked(W, q, rows, candidate).natural_map;
    if (candidate_residual >= residual) break;  // no progress: keep the better PGS answer
    lambda = candidate;
    residual = candidate_residual;
  }
  return residual;
}

}  // namespace taut
