// Derivatives of the signed SVD G = U diag(s) V^T of a tet's deformation gradient with respect to
// its node positions (paper A eqs. 13-16; docs/math.md §1-§2, with the gap clamp R1).
//
// Tet kinematics (docs/math.md §0.1): G = sum_n x_n r_n^T, n = 1..4, where r_1..r_3 are the rows of
// X0^-1 and r_4 = -(r_1 + r_2 + r_3). A 12-vector or a 3x12 matrix is ordered (x_1, x_2, x_3, x_4),
// each xyz, so column 3n + k is the derivative with respect to x_{n,k} (0-based n, k).
#pragma once

#include <array>

#include "plugin/common.h"
#include "plugin/signed_svd.h"
#include "plugin/tet_rest_data.h"

namespace taut {

// Per-element rest data: r_1..r_4 (docs/math.md §0.1).
using TetRestRows = std::array<Vec3, 4>;
// Current node positions x_1..x_4 of one tet [m].
using TetPositions = std::array<Vec3, 4>;
// d(column v_i of V)/dx: row j is dV_ji/dx, column 3n + k is x_{n,k}.
using Mat3x12 = Eigen::Matrix<double, 3, 12>;

// Default gap clamp of docs/math.md §2 R1 [s^2 units]: |s_i^2 - s_m^2| >= 1e-2.
constexpr double kDefaultSvdGapEpsilon = 1e-2;

// First-order change of the signed SVD for a perturbation dG: G + dG = (U + dU)(S + dS)(V + dV)^T.
struct SvdDifferential {
  Mat3 dU;  // U Omega^U
  Vec3 ds;  // ds_i = (U^T dG V)_ii
  Mat3 dV;  // V Omega^V
};

// Denominator of the pair (i, m), D_im = s_i^2 - s_m^2, clamped as in docs/math.md §2 R1: when
// |D| < epsilon it becomes sgn(D) epsilon with sgn(0) := +1, applied to the pair ordered
// min(i,m) < max(i,m) and negated for the other order, so Omega stays antisymmetric.
double CalcClampedGapDenominator(const Vec3& s, int i, int m, double epsilon);

// True when the clamp of CalcClampedGapDenominator changes D_im for some m != i.
bool IsSvdGapClampActive(const Vec3& s, int i, double epsilon);

// ds_i/dx_n = (r_n . v_i) u_i (paper A eq. 13; docs/math.md §1), as a 12-vector.
Vec12 CalcSingularValueGradient(const SignedSvd& svd, const TetRestRows& r, int i);

// dV_ji/dx_n = sum_{m != i} V_jm [s_m (r_n.v_i) u_m + s_i (r_n.v_m) u_i] / D_im for j = 1..3
// (Papadopoulo-Lourakis closed form, docs/math.md §2.2), with D_im clamped by R1.
Mat3x12 CalcSingularVectorGradient(const SignedSvd& svd, const TetRestRows& r, int i,
                                   double gap_epsilon = kDefaultSvdGapEpsilon);

// dU, ds, dV for one perturbation dG: P = U^T dG V, ds_i = P_ii, and for m != i
// Omega^V_mi = (s_m P_mi + s_i P_im) / D_im, Omega^U_mi = (s_i P_mi + s_m P_im) / D_im
// (docs/math.md §2.1), with D_im clamped by R1.
SvdDifferential CalcSvdDifferential(const SignedSvd& svd, const Mat3& dG,
                                    double gap_epsilon = kDefaultSvdGapEpsilon);

}  // namespace taut
