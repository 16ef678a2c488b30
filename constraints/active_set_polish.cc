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
  VecX candidate = lambda;
  for (int round = 0; round < settings.max_rounds && residual > settings.tolerance; ++round) {
    // Primal-dual active set: rows with min(lambda, w) decided by lambda > w (here lambda > 0 or
    // w < 0 of the current candidate) are active, w_A = 0; the others have lambda = 0.
    const VecX w = W * candidate + q;
    active.clear();
    for (int c = 0; c < m; ++c)
      if (candidate[c] - w[c] > 0.0) active.push_back(c);
    if (active.empty()) break;
    const int k = static_cast<int>(active.size());
    MatX W_AA(k, k);
    VecX rhs(k);
    for (int a = 0; a < k; ++a) {
      rhs[a] = -q[active[a]];
      for (int b = 0; b < k; ++b) W_AA(a, b) = W(active[a], active[b]);
      W_AA(a, a) += reg;
    }
    const VecX lambda_A = W_AA.ldlt().solve(rhs);
    if (!lambda_A.allFinite()) break;
    candidate.setZero();
    for (int a = 0; a < k; ++a) candidate[active[a]] = std::max(0.0, lambda_A[a]);
    if (settings.sweeps_per_round > 0) {
      PgsSettings fix = pgs;
      fix.max_sweeps = settings.sweeps_per_round;
      const PgsStats stats = SolvePgs(W, q, rows, candidate, fix);
      if (sweeps != nullptr) *sweeps += stats.sweeps;
    }
    const double candidate_residual =
        internal::CalcLcpResidualUnchecked(W, q, rows, candidate).natural_map;
    if (candidate_residual < residual) {  // keep the best answer seen
      lambda = candidate;
      residual = candidate_residual;
    }
  }
  return residual;
}

}  // namespace taut
