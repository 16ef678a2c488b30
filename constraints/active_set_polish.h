// Active-set refinement of a PGS solution of a unilateral LCP (subspace minimization).
#pragma once

#include <vector>

#include "constraints/pgs_solver.h"

namespace taut {

// Settings of the refinement.
struct ActiveSetPolishSettings {
  int max_rounds = 4;          // direct solves at most
  int sweeps_per_round = 10;   // PGS sweeps after each direct solve (to fix the active set)
  double tolerance = 1e-6;     // stop when the natural-map residual is below it
  double regularization = 1e-10;  // relative to max W_cc, added to the active block's diagonal
};

// PGS converges slowly on ill-conditioned W (long chains of limited elements). Guess the active
// set A = {c : lambda_c > 0 or w_c < 0} from the current iterate, solve W_AA lambda_A = -q_A
// directly (dense LDL^T, regularized), clamp lambda >= 0, and let a few PGS sweeps correct the
// set; repeat. Unilateral rows only (friction and bilateral rows: the plain PGS result is kept).
// Returns the final natural-map residual; lambda is updated in place.
double PolishActiveSet(const MatX& W, const VecX& q, const std::vector<PgsRow>& rows,
                       Eigen::Ref<VecX> lambda, const PgsSettings& pgs,
                       const ActiveSetPolishSettings& settings, int* sweeps = nullptr);

}  // namespace taut
