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

// Computes the signed SVD of G (docs/math.md §0.2: flip u_3 / v_3 and s_3 when det U or det V < 0).
SignedSvd CalcSignedSvd(const Mat3& G);

// Rotation of the polar decomposition G = R S taken from the signed SVD: R = U V^T (det R = +1,
// also for inverted G).
Mat3 CalcPolarRotation(const Mat3& G);

}  // namespace taut
