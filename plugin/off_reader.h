// Reader for ASCII OFF triangle/polygon surfaces (Geomview Object File Format).
#pragma once

#include <string>
#include <string_view>

#include "plugin/surface_mesh.h"

namespace taut {

// Reads an ASCII OFF file: a header "OFF" (also "COFF", "NOFF", "STOFF", ...: letters S, T, C, N
// before "OFF"), optionally followed on the same line by the counts, else a line
// "num_vertices num_faces [num_edges]"; then one vertex per line "x y z [extra values]" and one
// face per line "n i_1 ... i_n [colour]" with 0-based indices and n >= 3. Polygons are fan
// triangulated (i_1, i_k, i_k+1), keeping their winding. '#' starts a comment. Extra values after
// a vertex's coordinates or a face's indices (colours, normals, texture coordinates) are ignored.
// Throws MeshFileError "file:line: reason" on any malformed input (no crash on arbitrary bytes;
// reservations are capped by the file size). The surface is not checked for closure: call
// ValidateClosedSurface where a closed surface is needed. source is set to path.
SurfaceMesh ReadOffSurface(const std::string& path);

namespace internal {
// ReadOffSurface on text already in memory; name is used in messages and as the source.
SurfaceMesh ParseOffSurface(std::string_view text, const std::string& name);
}  // namespace internal

}  // namespace taut
