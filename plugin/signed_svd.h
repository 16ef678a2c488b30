// Signed singular value decomposition of a 3x3 matrix (Irving et al. 2004; docs/math.md §0.2).
#pragma once

#include "plugin/common.h"

namespace taut {

// G = U diag(s) V^T with U, V proper rotations, s sorted by |s| descending and
// sign(s[2]) = sign(det G). An inverted element therefore has s[2] < 0.
struct SignedSvd {
  Mat3 U;
  Vec3 s;
  Mat3 V;
};

// Computes the signed SVD of G in the convention of docs/math.md §0.2 (the ordinary SVD with its
// sign fixes), by the structure of McAdams et al. 2011 in double precision with exact rotations:
// G is scaled by a power of two to max |G_ij| in [1, 2); cyclic Jacobi diagonalizes G^T G =
// V diag(s^2) V^T (sorted descending); Givens QR of G V = U R gives s = diag(R), where R is
// diagonal up to round-off (its trailing 2x2 block is diagonalized once more when s_2 and s_3 are
// both below ~sqrt(eps) s_1). Signs are moved so that s_1, s_2 >= 0 and s_3 carries sign(det G).
// U and V are rotations for every finite G, rank-deficient ones included (G = 0: U = V = I,
// s = 0). A diagonal G with d_1 >= d_2 >= |d_3| gives U = V = I and s = d exactly; other diagonal
// G give signed permutation matrices and the sorted |d|. A non-finite G gives NaN in U, s and V.
// Accuracy (tests/signed_svd_test.cc): ||U diag(s) V^T - G||, ||U^T U - I|| and ||V^T V - I||
// of a few 1e-15 relative to ||G||; s within a few 1e-15 s_1 of Eigen's JacobiSVD, and a
// sliver's s_3 = 1e-6 s_1 to ~1e-10 relative.
SignedSvd CalcSignedSvd(const Mat3& G);

// R = U V^T of the signed SVD: the rotation of G's polar decomposition, a proper rotation also
// for inverted and singular G (plugin/polar_rotation.h takes it faster where det G > 0).
Mat3 CalcPolarRotationBySvd(const Mat3& G);

}  // namespace taut
