// Hexahedral rest lattice: node rest positions and trilinear hexes (8 node indices each).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "plugin/common.h"

namespace taut {

// Immutable rest geometry of a hex body. Local node order (docs/math.md §4.1): paper node
// n = 4(i-1) + 2(j-1) + k (i, j, k in {1, 2}) with s_n = ((-1)^i, (-1)^j, (-1)^k) is local index
// a = n - 1 = 4 bi + 2 bj + bk with bits bi = i - 1 etc., so node a sits at reference corner
// s_a = (2 bi - 1, 2 bj - 1, 2 bk - 1): a = 0 is (-,-,-), a = 1 is (-,-,+), a = 2 is (-,+,-),
// a = 4 is (+,-,-), a = 7 is (+,+,+). The rest map s -> X must have det(dX/ds) > 0.
struct HexLattice {
  std::vector<Vec3> nodes;                // (num_nodes) rest positions [m]
  std::vector<std::array<int, 8>> hexes;  // (num_hexes x 8) node indices, local order above
  std::string source = "hex lattice";     // file name or generator, used in error messages
};

// Reference corner s_a in {-1, 1}^3 of local node a (0..7), see HexLattice.
inline Vec3 HexCornerSign(int a) {
  return Vec3(2.0 * ((a >> 2) & 1) - 1.0, 2.0 * ((a >> 1) & 1) - 1.0, 2.0 * (a & 1) - 1.0);
}

// The 2x2x2 Gauss point q (0..7) in reference coordinates, s = HexCornerSign(q) / sqrt(3);
// every weight is 1.
Vec3 HexGaussPoint(int q);

// Rest Jacobian F = dX/ds = sum_a X_a (dN_a/ds)^T of a trilinear hex at s.
Mat3 CalcHexJacobian(const std::array<Vec3, 8>& X, const Vec3& s);

// Shape-function gradients dN_a/ds (row a) of the trilinear hex at s,
// N_a(s) = prod_k (1 + s_ak s_k) / 8.
Eigen::Matrix<double, 8, 3> CalcHexShapeGradients(const Vec3& s);

// Throws InputError naming the source and element when the lattice is empty, an index is out of
// range or repeated, a node is not finite, or a hex is inverted or degenerate:
// det F <= 1e-12 (longest edge)^3 at one of its Gauss points.
void ValidateHexLattice(const HexLattice& lattice);

// Box [min_corner, min_corner + size] cut into nx x ny x nz hexes. Nodes are numbered as in
// MakeBoxTetMesh (x fastest, BoxNodeIndex), so a hex lattice and a tet mesh of the same box
// share node indices and positions.
HexLattice MakeBoxHexLattice(const Vec3& size, int nx, int ny, int nz,
                             const Vec3& min_corner = Vec3::Zero());

}  // namespace taut
