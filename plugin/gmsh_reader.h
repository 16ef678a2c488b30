// Reader for Gmsh .msh tetrahedral meshes (ASCII format 2.2 and 4.1).
#pragma once

#include <string>
#include <string_view>

#include "plugin/tet_mesh.h"

namespace taut {

// Reads the 4-node tetrahedra (element type 4) of an ASCII Gmsh mesh, format version 2.2 (2.0 and
// 2.1 share its layout) or 4.1 (Gmsh reference manual, "MSH file format" and "Legacy formats").
// - $MeshFormat must come first; binary files and other versions are rejected.
// - $Nodes: every node is kept, in file order; node tags may be any distinct non-negative
//   integers (non-contiguous in 4.1), and element node tags are mapped to these indices.
// - $Elements: one element per line. Type 4 lines must carry exactly 4 node tags; every other
//   type (points, lines, triangles, ...) is skipped. A tet listed twice with the same nodes (2.2
//   writes an element once per physical group) is kept once. No type-4 element is an error, which
//   names the element types that were found (10-node tets, type 11, are not supported).
// - Other sections ($Entities, $PhysicalNames, $NodeData, ...) are skipped.
// Gmsh orders tet nodes with det[X2-X1, X3-X1, X4-X1] > 0, the opposite of docs/math.md §0.1, so
// most tets get nodes 0 and 1 swapped (internal::OrientAndValidateTetMesh); the mesh is then
// validated. mesh.source is path. Throws MeshFileError ("file:line: reason") on any parse error.
TetMesh ReadGmshMesh(const std::string& path);

namespace internal {
// Parses .msh text held in memory; name appears in messages and as mesh.source (fuzzing entry).
TetMesh ParseGmshMesh(std::string_view text, const std::string& name);
}  // namespace internal

}  // namespace taut
