// Legacy ASCII VTK writer for hex lattices (VTK_HEXAHEDRON cells), for viewing in ParaView.
#pragma once

#include <string>
#include <vector>

#include "plugin/hex_lattice.h"

namespace taut {

// VTK_HEXAHEDRON cell type id.
constexpr int kVtkHexahedron = 12;

// VTK numbers a hexahedron's corners counter-clockwise around the bottom face s3 = -1 and then
// the top face: (---), (+--), (++-), (-+-), (--+), (+-+), (+++), (-++) as signs of (s1, s2, s3).
// Our local node a = 4 bi + 2 bj + bk (hex_lattice.h), so VTK corner v is our local node
// kVtkHexFromLocal[v]. Both orders are right-handed, so det F > 0 gives a positive VTK volume.
inline constexpr int kVtkHexFromLocal[8] = {0, 4, 6, 2, 1, 5, 7, 3};

// Writes the lattice as a legacy ASCII "DATASET UNSTRUCTURED_GRID" of VTK_HEXAHEDRON cells in
// VTK's node order (above). Points are `positions` (one per node, e.g. the deformed state) when
// given, else the rest nodes; reals are written with std::to_chars (shortest exact text). Throws
// InputError on a size mismatch, an out-of-range node index or when the file cannot be written
// (naming the path).
void WriteVtkHexLattice(const std::string& path, const HexLattice& lattice,
                        const std::vector<Vec3>* positions = nullptr);

}  // namespace taut
