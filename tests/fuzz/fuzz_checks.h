// Checks shared by the mesh reader fuzz targets (libFuzzer): what a mesh that parsed without
// InputError must satisfy. A failed check aborts, which libFuzzer reports as a crash.
#pragma once

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "plugin/hex_voxelizer.h"
#include "plugin/tet_mesh.h"
#include "plugin/tet_rest_data.h"

namespace taut::fuzz {

// The input bytes as text.
inline std::string_view AsText(const uint8_t* data, size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

// Aborts with a message when cond is false.
inline void Require(bool cond, const char* what) {
  if (cond) return;
  std::fprintf(stderr, "fuzz invariant violated: %s\n", what);
  std::abort();
}

// A parsed tet mesh must already be valid (finite nodes, indices in range, every tet positive):
// validation and the rest data may not throw.
inline void CheckParsedTetMesh(const TetMesh& mesh) {
  try {
    const TetRestData rest = CalcTetRestData(mesh);
    for (const TetRestElement& e : rest.elements) Require(e.volume > 0.0, "tet volume > 0");
  } catch (const InputError& e) {
    std::fprintf(stderr, "parsed mesh fails validation: %s\n", e.what());
    std::abort();
  }
}

// A parsed surface must have finite vertices and in-range, distinct indices. When it is also a
// closed surface, it is voxelized on a grid of at most 7^3 cells (InputError is allowed there:
// no cell inside, extents that overflow) and the lattice's indices are checked.
inline void CheckParsedSurface(const SurfaceMesh& mesh) {
  const int n = static_cast<int>(mesh.vertices.size());
  for (const Vec3& v : mesh.vertices) Require(v.allFinite(), "finite vertex");
  for (const Triangle& t : mesh.triangles)
    for (int a = 0; a < 3; ++a) Require(t[a] >= 0 && t[a] < n, "triangle index in range");
  try {
    ValidateClosedSurface(mesh);
    const double cell = CalcSurfaceBounds(mesh).sizes().maxCoeff() / 6.0;
    const HexLattice lattice = VoxelizeSurface(mesh, cell);
    const int m = static_cast<int>(lattice.nodes.size());
    for (const auto& hex : lattice.hexes)
      for (int a = 0; a < 8; ++a) Require(hex[a] >= 0 && hex[a] < m, "hex index in range");
  } catch (const InputError&) {
  }
}

}  // namespace taut::fuzz
