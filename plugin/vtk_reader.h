// Reader for legacy VTK unstructured grids holding tetrahedra.
#pragma once

#include <string>
#include <string_view>

#include "plugin/tet_mesh.h"

namespace taut {

// Reads the VTK_TETRA cells (type 10) of a legacy ASCII VTK file ("VTK User's Guide", file
// formats): header "# vtk DataFile Version x.y", a title line, ASCII, "DATASET UNSTRUCTURED_GRID",
// then POINTS (any numeric type), CELLS and CELL_TYPES. CELLS may use the classic layout
// ("<npts> <ids...>" per cell) or the version 5.1 layout (OFFSETS and CONNECTIVITY arrays).
// Tokens may be spread over lines freely; keywords are case-insensitive. FIELD and METADATA blocks
// in the dataset part are skipped, and reading stops at POINT_DATA or CELL_DATA. Every point is
// kept; cells of other types (triangles, vertices, ...) are skipped after their point ids are
// range-checked. VTK orders tet nodes with det[X2-X1, X3-X1, X4-X1] > 0, the opposite of
// docs/math.md §0.1, so tets get nodes 0 and 1 swapped where needed
// (internal::OrientAndValidateTetMesh) and the mesh is validated. mesh.source is path. Throws
// MeshFileError ("file:line: reason") on any parse error, including binary files and files without
// tetrahedra.
TetMesh ReadVtkMesh(const std::string& path);

namespace internal {
// Parses VTK text held in memory; name appears in messages and as mesh.source (fuzzing entry).
TetMesh ParseVtkMesh(std::string_view text, const std::string& name);
}  // namespace internal

}  // namespace taut
