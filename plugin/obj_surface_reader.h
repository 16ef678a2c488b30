// Reader for Wavefront OBJ triangle surfaces (through tinyobjloader).
#pragma once

#include <string>

#include "plugin/surface_mesh.h"

namespace taut {

// Reads the vertices ("v") and faces ("f", all groups and objects merged) of an OBJ file with
// tinyobjloader (double precision), triangulating polygons; normals, texture coordinates, lines,
// points and materials are ignored (no .mtl file is opened). Negative (relative) indices are
// resolved by tinyobjloader. Throws InputError "file: reason" (a MeshFileError with line 0) when
// the file cannot be opened or parsed, a vertex is not finite, an index is out of range or there
// are no triangles. The surface is not checked for closure (see ValidateClosedSurface). source is
// set to path.
SurfaceMesh ReadObjSurface(const std::string& path);

}  // namespace taut
