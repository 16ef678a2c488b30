// Reader for Wavefront OBJ triangle surfaces (through tinyobjloader).
#pragma once

#include <string>
#include <string_view>

#include "plugin/surface_mesh.h"

namespace taut {

// Reads the vertices ("v") and faces ("f", all groups and objects merged) of an OBJ file;
// normals, texture coordinates, lines, points, materials and every other statement are ignored
// (no .mtl file is opened). Lines end at "\n", "\r\n" or "\r". Vertex lines must start with
// three finite numbers x y z (read with std::from_chars; extra values such as colours are
// ignored); face lines must hold 3 to 255 vertex references "i", "i/t", "i//n" or "i/t/n" with
// 1-based or negative (relative) vertex indices. The reader checks these lines itself and hands
// tinyobjloader only canonical "v"/"f" lines and the "o"/"g" lines, which it uses to resolve
// relative indices and groups. Polygons are fan triangulated (i_1, i_k, i_k+1), keeping their
// winding. Throws InputError "file: reason (line N)" (a MeshFileError with line 0) when the file
// cannot be opened or parsed, a coordinate is not a finite number, a face has too few or too many
// vertices, an index is 0 or out of range, a triangle repeats a vertex or there are no triangles.
// The surface is not checked for closure (see ValidateClosedSurface). source is set to path.
SurfaceMesh ReadObjSurface(const std::string& path);

namespace internal {
// ReadObjSurface on text already in memory; name is used in messages and as the source (fuzzing
// entry point).
SurfaceMesh ParseObjSurface(std::string_view text, const std::string& name);
}  // namespace internal

}  // namespace taut
