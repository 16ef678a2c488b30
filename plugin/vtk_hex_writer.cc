#include "plugin/vtk_hex_writer.h"

#include <charconv>
#include <fstream>

namespace taut {

namespace {
// Appends the shortest decimal text that reads back as exactly x.
void AppendReal(std::string& out, double x) {
  char buffer[32];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof(buffer), x);
  out.append(buffer, ec == std::errc() ? end : buffer);
}
}  // namespace

void WriteVtkHexLattice(const std::string& path, const HexLattice& lattice,
                        const std::vector<Vec3>* positions) {
  const std::vector<Vec3>& points = positions != nullptr ? *positions : lattice.nodes;
  TAUT_DEMAND(points.size() == lattice.nodes.size(), "VTK file '", path, "': ", points.size(),
              " positions given for ", lattice.nodes.size(), " nodes of '", lattice.source, "'");
  const std::size_t num_points = points.size(), num_cells = lattice.hexes.size();
  std::string out = "# vtk DataFile Version 3.0\n" + lattice.source +
                    "\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS " + std::to_string(num_points) +
                    " double\n";
  for (const Vec3& p : points) {
    for (int k = 0; k < 3; ++k) {
      AppendReal(out, p[k]);
      out += k < 2 ? ' ' : '\n';
    }
  }
  out += "CELLS " + std::to_string(num_cells) + " " + std::to_string(9 * num_cells) + "\n";
  for (std::size_t c = 0; c < num_cells; ++c) {
    out += '8';
    for (int v = 0; v < 8; ++v) {
      const int node = lattice.hexes[c][kVtkHexFromLocal[v]];
      TAUT_DEMAND(node >= 0 && static_cast<std::size_t>(node) < num_points, "VTK file '", path,
                  "': hex ", c, " refers to node ", node, " but there are ", num_points, " points");
      out += ' ' + std::to_string(node);
    }
    out += '\n';
  }
  out += "CELL_TYPES " + std::to_string(num_cells) + "\n";
  for (std::size_t c = 0; c < num_cells; ++c) out += std::to_string(kVtkHexahedron) + "\n";
  std::ofstream file(path, std::ios::binary);
  TAUT_DEMAND(file.good(), "cannot open VTK file '", path, "' for writing");
  file << out;
  TAUT_DEMAND(file.good(), "failed writing VTK file '", path, "'");
}

}  // namespace taut
