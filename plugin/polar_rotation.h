// The rotation of the polar decomposition of a 3x3 matrix (docs/math.md §0.2).
#pragma once

#include "plugin/common.h"

namespace taut {

// Rotation R of the polar decomposition G = R S (S symmetric), det R = +1 for every finite G.
// For det G > 0 it is G's orthogonal polar factor, computed by Newton's iteration
//   X_0 = G,  X_{k+1} = 1/2 (zeta_k X_k + X_k^-T / zeta_k)
// (Higham 1986), with zeta_k = (||X_k^-1||_F / ||X_k||_F)^(1/2) while X_k is far from orthogonal
// and 1 near it; it stops once ||X_{k+1} - X_k||_F <= 1e-8 (the iteration converges
// quadratically, so X is then orthogonal to round-off). Inverted and near-singular G
// (det G <= 1e-12 ||G||_F^3),
// non-finite G and the rare G that needs more than 10 iterations take R = U V^T from the signed
// SVD (plugin/signed_svd.h), which also holds for them. Both agree to a few 1e-15 on
// well-conditioned G (tests/polar_rotation_test.cc); the iteration costs 3-5 cofactor inverses,
// about a quarter of the SVD (bench/svd_bench.cc).
Mat3 CalcPolarRotation(const Mat3& G);

}  // namespace taut
