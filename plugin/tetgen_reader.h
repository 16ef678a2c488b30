// Reader for TetGen's .node/.ele tetrahedral meshes.
#pragma once

#include <string>
#include <string_view>

#include "plugin/tet_mesh.h"

namespace taut {

// Reads base.node and base.ele, given "base.node", "base.ele" or "base" (e.g. "beam.1").
// Format (TetGen manual, "File formats"): '#' starts a comment, blank lines are ignored.
//   .node: "<#points> [<dimension = 3> [<#attributes> [<boundary markers 0|1>]]]", then one line
//          per point "<point #> <x> <y> <z> [attributes] [marker]".
//   .ele:  "<#tets> [<nodes per tet = 4> [<region attribute 0|1>]]", then one line per tet
//          "<tet #> <n1> <n2> <n3> <n4> [attribute]".
// Point numbers start at 0 or 1 (the first point decides) and must be consecutive; the .ele node
// indices use the same base. Attributes, markers and tet numbers are checked but dropped;
// 10-node tets are rejected. Tets are then oriented positively (nodes 0 and 1 swapped where the
// signed volume is negative, see internal::OrientAndValidateTetMesh) and validated.
// mesh.source is the .ele path. Throws MeshFileError ("file:line: reason") on any parse error.
TetMesh ReadTetGenMesh(const std::string& node_or_base_path);

namespace internal {
// Parses .node and .ele text held in memory; the names appear in messages (fuzzing entry point).
TetMesh ParseTetGenMesh(std::string_view node_text, const std::string& node_name,
                        std::string_view ele_text, const std::string& ele_name);
}  // namespace internal

}  // namespace taut
