// Full curvature of a frame-dependent strain-limit row, including the frame factor's second
// derivative (issue 11 item 3; docs/math.md §5.9).
//
// The hyperbolic and ellipsoid rows are C = 1 - sigma (s_i - 1) a(v_i), sigma = +1 on the upper
// bound and -1 on the lower, with the frame factor a = sqrt(v_i^T M v_i): M = Q K^2 Q^T for the
// ellipsoid row, M = kappa_j^2 q_j q_j^T for the hyperbolic row (j, i). Their exact second
// derivative is
//   -d^2 C = sigma [ a d^2 s_i + 2 ds_i da + (s_i - 1) d^2 a ],
// where d^2 a needs the second-order perturbation of the eigenvector v_i of F^T F. In principal
// coordinates P = U^T dF V (F = U diag(s) V^T), C1 = S P + P^T S and C2 = 2 P^T P are the first
// and second derivatives of V^T F^T F V; with g_j = 1/(s_i^2 - s_j^2) (gap clamp R1):
//   v'_j  = g_j (C1)_ji                                                      (j != i)
//   v''_j = 2 g_j sum_{k != i} g_k (C1)_jk (C1)_ki - 2 g_j^2 (C1)_ii (C1)_ji + g_j (C2)_ji
//   v''_i = -sum_{j != i} g_j^2 (C1)_ji^2
//   a' = (M~ v')_i / a,   a'' = (v'^T M~ v' + (M~ e_i) . v'') / a - a'^2 / a,  M~ = V^T M V.
// constraints/strain_limit_curvature.h keeps only the first term; this adds the frame terms,
// which are large where singular values are close (every element of a beam strained by a few
// percent) and which the Newton matrix needs there (docs/solver.md, the anisotropic beam).
#pragma once

#include "constraints/singular_value_hessian.h"
#include "constraints/strain_limit_rows.h"

namespace taut {

// True when params.full_frame_curvature asks for it and the projection's rows depend on the
// principal frame through a(v_i) (hyperbolic, or ellipsoid with unequal weights).
bool HasStrainFrameCurvature(const StrainLimitParams& params);

// True when the rows' curvature term is their whole second derivative: the frame factor's term is
// in (HasStrainFrameCurvature), or the rows do not depend on the frame (ellipsoid rows of equal
// weights on every axis, C a function of one stretch s_i). The primal path's model steps trust it.
bool HasExactStrainCurvature(const StrainLimitParams& params);

// -d^2 C/dP^2 of the row `key` (hyperbolic or ellipsoid) as a symmetric 9x9 matrix over vec(P),
// P = U^T dF V (row-major index 3 x + y for P_xy), not clamped; Q is the element's limit frame.
// Zero when the frame factor vanishes (a hyperbolic row at its |V'_ji| kink never binds).
Mat9 CalcPrincipalStrainRowCurvature(const SignedSvd& svd, const Mat3& Q,
                                     const StrainLimitParams& params, const StrainLimitKey& key);

// The positive semi-definite part of a symmetric 9x9 matrix (negative eigenvalues set to 0); a
// matrix whose eigenvalues are all above -kept_fraction max |H_kk| is returned as it is.
Mat9 ClampNegativeModes(const Mat9& H, double kept_fraction = 1e-10);

// kept_fraction of the element sums of the frame curvature (docs/math.md §5.9): negative modes
// down to half the sum's largest diagonal entry stay, so the eigen-decomposition runs only for
// strongly indefinite sums. On the soft anisotropic beam the Newton iterations per step stay the
// same (19.8 -> 19.9) and the step is 1.34x faster than with the exact clamp (1e-10).
constexpr double kFrameCurvatureKeptNegativeFraction = 0.5;

// H over vec(P) mapped to the 12 node coordinates of a tet: P = sum_n (U^T dx_n)(V^T r_n)^T.
Mat12 MapPrincipalHessianToTet(const Mat9& H, const SignedSvd& svd, const TetRestRows& r);

}  // namespace taut
