// Tetrahedral rest mesh: node rest positions and tets (4 node indices each).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "plugin/common.h"

namespace taut {

// Immutable rest geometry of a tet body. Tets are positively oriented:
// det[X1-X4, X2-X4, X3-X4] > 0 (docs/math.md §0.1 node order).
struct TetMesh {
  std::vector<Vec3> nodes;               // (num_nodes) rest positions [m]
  std::vector<std::array<int, 4>> tets;  // (num_tets x 4) node indices
  std::string source = "mesh";           // file name or generator, used in error messages
};

// A boundary triangle of a tet mesh, wound so its normal points out of the body.
using Triangle = std::array<int, 3>;

// Signed volume of the tet (a, b, c, d): det[a-d, b-d, c-d] / 6.
double CalcTetSignedVolume(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

// Throws InputError naming the source and element when the mesh is empty, an index is out of
// range or repeated, a node is not finite, or a tet is inverted (negative volume) or degenerate
// (volume below 1e-12 of its longest edge cubed).
void ValidateTetMesh(const TetMesh& mesh);

// Faces used by exactly one tet, outward wound (counter-clockwise seen from outside).
std::vector<Triangle> CalcBoundaryFaces(const TetMesh& mesh);

// Nodes that lie on a boundary face, sorted ascending.
std::vector<int> CalcBoundaryNodes(const TetMesh& mesh);

}  // namespace taut
