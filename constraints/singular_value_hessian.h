// Second derivative of one signed singular value of a 3x3 matrix, as an eigen-decomposition, and
// its map to the node space of a tet (the curvature of strain-limit rows, issue 11 item 3).
//
// With the signed SVD F = U diag(s) V^T (docs/math.md §0.2) and P = U^T dF V, the second-order
// change of s_i is (checked against FD in tests/singular_value_hessian_test.cc)
//   d^2 s_i[dF, dF] = sum_{j != i} [ a_j^2 / (s_i - s_j) + b_j^2 / (s_i + s_j) ],
//   a_j = (P_ij + P_ji)/sqrt2 = <dF, S_j>,  S_j = (u_i v_j^T + u_j v_i^T)/sqrt2   (symmetric mode)
//   b_j = (P_ij - P_ji)/sqrt2 = <dF, A_j>,  A_j = (u_i v_j^T - u_j v_i^T)/sqrt2   (antisymmetric)
// and 0 on the other five directions (the diagonal modes u_k v_k^T and the (j, k) pair modes).
// The four modes are Frobenius-orthonormal, so the Hessian's eigenvalues are exactly
// 1/(s_i - s_j) and 1/(s_i + s_j). Both blow up at repeated values (s_i = s_j) or, for an
// inverted tet, at s_i = -s_j; the gap clamp of docs/math.md §2 R1 bounds them: |s_i -+ s_j| >= rho
// with rho = epsilon / (|s_i| + |s_j|), i.e. |s_i^2 - s_j^2| >= epsilon.
//
// Tet node space (docs/math.md §0.1): F = sum_n x_n r_n^T, so <dF, M> = sum_n dx_n . (M r_n) and
// each mode contributes lambda (M r_a)(M r_b)^T to the 3x3 block of nodes (a, b).
#pragma once

#include <array>

#include "constraints/svd_derivatives.h"
#include "plugin/common.h"
#include "plugin/signed_svd.h"

namespace taut {

// vec(F) in row-major order: entry F(k, l) has index 3k + l.
using Mat9 = Eigen::Matrix<double, 9, 9>;

// d^2 s_i / dF^2 = sum_k eigenvalues[k] modes[k] (x) modes[k] (k = symmetric and antisymmetric
// mode of each j != i), zero on the orthogonal complement.
struct SingularValueHessian {
  std::array<Mat3, 4> modes;          // S_j, A_j for the two j != i; Frobenius-orthonormal
  std::array<double, 4> eigenvalues;  // 1/(s_i - s_j), 1/(s_i + s_j), gaps clamped [1/s]
};

// Modes and eigenvalues of d^2 s_i / dF^2 at the signed SVD (gap clamp R1 with `gap_epsilon`
// in s^2 units; 0 = exact, unbounded at repeated values).
SingularValueHessian CalcSingularValueHessian(const SignedSvd& svd, int i,
                                              double gap_epsilon = kDefaultSvdGapEpsilon);

// The Hessian as a dense 9x9 matrix over vec(F) (row-major index 3k + l).
Mat9 CalcDenseSingularValueHessian(const SingularValueHessian& hessian);

// scale * d^2 s_i / dx^2 of a tet (12x12, node-major xyz), with x entering through
// F = sum_n x_n r_n^T. With clamp_negative, modes whose scaled eigenvalue is negative are
// dropped: the result is the positive semi-definite part [scale d^2 s_i/dx^2]_+ .
Mat12 CalcTetSingularValueHessian(const SingularValueHessian& hessian, const TetRestRows& r,
                                  double scale, bool clamp_negative);

}  // namespace taut
