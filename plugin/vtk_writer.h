// Legacy ASCII VTK writers for tet meshes and triangle surfaces, for viewing in ParaView.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "plugin/tet_mesh.h"

namespace taut {

// Named per-point and per-cell data written next to the geometry. Names must be non-empty and
// free of blanks (legacy VTK splits on whitespace); each array needs one entry per point or cell.
struct VtkFields {
  std::vector<std::pair<std::string, std::vector<double>>> point_scalars;  // (num_points) each
  std::vector<std::pair<std::string, std::vector<Vec3>>> point_vectors;    // (num_points) each
  std::vector<std::pair<std::string, std::vector<double>>> cell_scalars;   // (num_cells) each
};

// Writes mesh as a legacy ASCII "DATASET UNSTRUCTURED_GRID" of VTK_TETRA cells. Points are
// positions (e.g. the deformed state, one per node) when given, else the rest nodes. Reals are
// written with std::to_chars (shortest text that reads back to the same double), so a file read
// back with ReadVtkMesh reproduces them bit for bit. Tets are written in VTK's node order (nodes 0
// and 1 swapped, so VTK sees det[X2-X1, X3-X1, X4-X1] > 0 for a positive tet of docs/math.md §0.1),
// which ReadVtkMesh undoes. Throws InputError on mismatched sizes, bad field names, out-of-range
// node indices, or when the file cannot be written (naming the path).
void WriteVtkMesh(const std::string& path, const TetMesh& mesh,
                  const std::vector<Vec3>* positions = nullptr, const VtkFields& fields = {});

// Writes a triangle surface (e.g. a surface embedded in a hex body) as a legacy ASCII unstructured
// grid of VTK_TRIANGLE cells, keeping the triangles' winding. Same number format and errors as
// WriteVtkMesh; cell fields have one entry per triangle.
void WriteVtkSurface(const std::string& path, const std::vector<Vec3>& positions,
                     const std::vector<Triangle>& triangles, const VtkFields& fields = {});

}  // namespace taut
