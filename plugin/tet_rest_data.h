// Per-element rest quantities of a tet mesh, computed once (docs/math.md §0.1).
#pragma once

#include <array>
#include <vector>

#include "plugin/tet_mesh.h"

namespace taut {

// Rest data of one tet: G = sum_n x_n r_n^T, with r_1..r_3 the rows of X0^-1
// (X0 = [X1-X4, X2-X4, X3-X4]) and r_4 = -(r_1 + r_2 + r_3) (docs/math.md §0.1).
struct TetRestElement {
  std::array<Vec3, 4> r;  // shape-function gradients [1/m]
  double volume = 0.0;    // rest volume [m^3], > 0
};

// Rest data of every tet in a mesh. Immutable once built; shareable between bodies.
struct TetRestData {
  std::vector<TetRestElement> elements;  // (num_tets)
};

// Validates the mesh (ValidateTetMesh) and computes r_n and rest volumes of every tet.
TetRestData CalcTetRestData(const TetMesh& mesh);

// Deformation gradient G = sum_n x_n r_n^T of one tet from its rows r_n and node positions x
// (paper A eq. 3; docs/math.md §0.1).
Mat3 CalcTetDeformationGradient(const std::array<Vec3, 4>& r, const std::array<Vec3, 4>& x);
// The same from the element's rest data.
inline Mat3 CalcTetDeformationGradient(const TetRestElement& rest, const std::array<Vec3, 4>& x) {
  return CalcTetDeformationGradient(rest.r, x);
}

}  // namespace taut
