// Curvature of one strain-limit row for the SQP metric: the lagged geometric stiffness
// h lambda [-d^2 C/dx^2]_+ (issue 11 item 3; docs/math.md §5.9).
//
// Every row of constraints/strain_limit_rows.h is, with its frame factor frozen,
//   C_max = 1 - kappa_eff (s_i - 1),   C_min = 1 + kappa_eff (s_i - 1),   kappa_eff = |dC/ds_i|,
//   hyperbolic (j, i): kappa^j |V'_ji|      ellipsoid (i): ||K V' e_i||
//   linear interp (i): 1 / |L - 1|          orthogonal (j, i): 1 / |d^j|
// (docs/math.md §3). The metric keeps the dominant term, the one through s_i:
//   -d^2 C/dx^2 ~ +kappa_eff d^2 s_i/dx^2 (upper bound),  -kappa_eff d^2 s_i/dx^2 (lower bound),
// dropping the |V'_ji| curvature (a lagged Gauss-Newton-like approximation: it only changes the
// metric, not the converged step), and clamps negative modes so the block is positive
// semi-definite. For the isotropic ellipsoid rows (equal kappa) it is the exact curvature
// before the clamp. d^2 s_i/dx^2: constraints/singular_value_hessian.h (gap clamp R1).
#pragma once

#include "constraints/singular_value_hessian.h"
#include "constraints/strain_limit_rows.h"

namespace taut {

// kappa_eff = |dC/ds_i| >= 0 of the row `key` on principal direction i, at V' = Q^T V.
double CalcStrainRowStretchSlope(const Mat3& V_prime, int i, const StrainLimitParams& params,
                                 const StrainLimitKey& key);

// [-d^2 C/dx^2]_+ of the row `key` of a tet (12x12, node-major xyz, PSD) at the signed SVD of
// its F, with the gap clamp params.svd_gap_epsilon; Q is the element's limit frame.
Mat12 CalcStrainLimitRowCurvature(const TetRestRows& r, const SignedSvd& svd, const Mat3& Q,
                                  const StrainLimitParams& params, const StrainLimitKey& key);

}  // namespace taut
