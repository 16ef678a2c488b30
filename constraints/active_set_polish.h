// Active-set refinement of a PGS solution of a unilateral LCP (subspace minimization).
#pragma once

#include <vector>

#include "constraints/pgs_solver.h"

namespace taut {

// Settings of the refinement.
struct ActiveSetPolishSettings {
  int max_rounds = 8;          // direct solves at most
  int sweeps_per_round = 0;    // PGS sweeps after each direct solve (0: pure active-set steps)
  double tolerance = 1e-6;     // stop when the natural-map residual is below it
  double regularization = 1e-10;  // relative to max W_cc, added to the active block's diagonal
};

// PGS converges slowly on ill-conditioned W (long chains of limited elements). Primal-dual
// active-set steps from the PGS answer: A = {c : lambda_c - w_c > 0}, solve W_AA lambda_A = -q_A
// directly (dense LDL^T, regularized), lambda = max(0, .) elsewhere 0, optionally a few PGS
// sweeps; repeat, keeping the answer with the smallest residual. Unilateral rows only (friction and bilateral rows: the plain PGS result is kept).
// Returns the final natural-map residual; lambda is updated in place.
double PolishActiveSet(const MatX& W, const VecX& q, const std::vector<PgsRow>& rows,
                       Eigen::Ref<VecX> lambda, const PgsSettings& pgs,
                       const ActiveSetPolishSettings& settings, int* sweeps = nullptr);

}  // namespace taut
