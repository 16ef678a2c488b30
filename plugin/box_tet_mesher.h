// Procedural box/beam tetrahedralization with consistent diagonals.
#pragma once

#include "plugin/tet_mesh.h"

namespace taut {

// Box [min_corner, min_corner + size] cut into nx x ny x nz cubes, each split into the 6 Kuhn
// tetrahedra around its (0,0,0)-(1,1,1) diagonal. Neighbouring cubes then share face diagonals,
// so the mesh is conforming. Nodes are numbered x fastest: node(i,j,k) = i + (nx+1)(j + (ny+1)k).
TetMesh MakeBoxTetMesh(const Vec3& size, int nx, int ny, int nz,
                       const Vec3& min_corner = Vec3::Zero());

// Index of grid node (i, j, k) in a mesh made by MakeBoxTetMesh with nx, ny cells.
inline int BoxNodeIndex(int i, int j, int k, int nx, int ny) {
  return i + (nx + 1) * (j + (ny + 1) * k);
}

}  // namespace taut
