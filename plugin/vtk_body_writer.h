// Legacy ASCII VTK file of a deformable body as it is now, for viewing in ParaView.
#pragma once

#include <string>

#include "plugin/deformable_body.h"

namespace taut {

// Writes the body's elements at its current positions x [m]: a tet body as VTK_TETRA cells
// (WriteVtkMesh), a hex body as VTK_HEXAHEDRON cells (WriteVtkHexLattice), with the same exact
// number format, so ReadVtkMesh of a tet body's file gives back x bit for bit. Throws InputError
// for another element model or when the file cannot be written (naming the path).
void WriteVtk(const DeformableBody& body, const std::string& path);

}  // namespace taut
