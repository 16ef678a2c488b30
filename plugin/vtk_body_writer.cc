#include "plugin/vtk_body_writer.h"

#include <vector>

#include "plugin/vtk_hex_writer.h"
#include "plugin/vtk_writer.h"

namespace taut {

void WriteVtk(const DeformableBody& body, const std::string& path) {
  std::vector<Vec3> positions(body.num_nodes());
  for (int i = 0; i < body.num_nodes(); ++i) positions[i] = body.node_position(i);
  if (const TetMesh* mesh = body.rest_tet_mesh()) {
    WriteVtkMesh(path, *mesh, &positions);
  } else if (const HexLattice* lattice = body.rest_hex_lattice()) {
    WriteVtkHexLattice(path, *lattice, &positions);
  } else {
    throw InputError(internal::Concat("VTK file '", path, "': body '", body.name(),
                                      "' is neither a tet nor a hex body"));
  }
}

}  // namespace taut
