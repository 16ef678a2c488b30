// Active-set refinement of a PGS solution of a unilateral LCP (subspace minimization).
#pragma once

#include <vector>

#include "constraints/pgs_solver.h"

namespace taut {

// Settings of the refinement.
struct ActiveSetPolishSettings {
  int max_rounds = 8;            // Newton steps at most
  int sweeps_per_round = 5;      // PGS sweeps after each Newton step (fix the free set)
  double tolerance = 1e-6;       // stop when the natural-map residual is below it
  double regularization = 1e-8;  // times W_cc, added to each row of the free block's diagonal
};

// PGS converges slowly on ill-conditioned W (long chains of limited elements). Projected Newton
// steps on the QP objective f = 1/2 l^T W l + q^T l over l >= 0, from the PGS answer: free set
// F = {l_c > 0 or w_c < 0}, direction d = -W_FF^-1 w_F (dense LDL^T, regularized row by row
// relative to each W_cc, so the step does not depend on the rows' scales), projected
// backtracking until f decreases, optionally a few PGS sweeps; repeat. f never increases.
// Unilateral rows only (friction and bilateral rows: the plain PGS result is kept). Returns the
// final natural-map residual; lambda is updated in place.
double PolishActiveSet(const MatX& W, const VecX& q, const std::vector<PgsRow>& rows,
                       Eigen::Ref<VecX> lambda, const PgsSettings& pgs,
                       const ActiveSetPolishSettings& settings, int* sweeps = nullptr);

}  // namespace taut
