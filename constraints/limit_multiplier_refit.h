// Least-squares multipliers of the active limit rows at a fixed velocity (docs/math.md §5.10,
// refitted multipliers): the convergence certificate asks only that SOME lambda satisfies the KKT
// conditions with v, and with more limit rows than DOFs the split of the force among redundant
// rows is not unique; the augmented-Lagrangian update moves force off a row that is no longer at
// its bound only at a rate set by its penalty against the rows that share its motion.
#pragma once

#include <vector>

#include "constraints/island_rows.h"

namespace taut {

// lambda <- the multipliers with, over the free blocks of every body,
//   min_{lambda_a >= 0} || A (v - v*) - J_o^T lambda_o - J_a^T lambda_a ||^2,
// a = the unilateral limit rows with C <= violation_tolerance (at their bound within the
// tolerance), o = every other row with its lambda kept, except slack unilateral limit rows
// (C > violation_tolerance), whose lambda becomes 0. Projected coordinate descent (Gauss-Seidel
// on J_a J_a^T) from lambda, at most `max_sweeps` sweeps; stops when the residual is below
// target_stationarity ||A (v - v*)|| (stationarity is then at most target_stationarity), when a
// sweep changes no multiplier by more than 1e-9 of the largest, or when the residual, falling at
// the last sweep's rate over the sweeps left, would stay above 2 target_stationarity ||A (v - v*)||
// (a stall: such a refit cannot certify). a_dv[b] = A_b (v_b - v*_b) at the v the rows were
// collected at (CalcVelocityChangeMomentum, constraints/kkt_certificate.h).
void RefitLimitMultipliers(const std::vector<IslandBody*>& bodies, const IslandRows& rows,
                           const std::vector<VecX>& a_dv, double violation_tolerance,
                           double target_stationarity, int max_sweeps, VecX& lambda);

}  // namespace taut
