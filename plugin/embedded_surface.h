// A triangle surface embedded in a regular hex lattice: each vertex follows the lattice through
// the trilinear shape functions of one hex.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "plugin/hex_lattice.h"
#include "plugin/surface_mesh.h"

namespace taut {

// Where one surface vertex sits in the lattice: its hex and the 8 trilinear weights
// N_a(s) = prod_k (1 + s_ak s_k) / 8 (local node order of HexLattice) at its reference
// coordinates s. Inside the hex s is in [-1, 1]^3 and the weights in [0, 1]; for a vertex outside
// every hex s is outside that cube and the weights extrapolate (some negative or > 1). They always
// sum to 1, and x = sum_a N_a x_a reproduces any affine map of the nodes exactly.
struct EmbeddedVertex {
  int hex = -1;                     // index into HexLattice::hexes
  std::array<double, 8> weights{};  // N_a(s), a = 0..7
  Vec3 s = Vec3::Zero();            // reference coordinates in the hex
};

// A surface carried by a hex lattice.
struct EmbeddedSurface {
  std::vector<EmbeddedVertex> vertices;  // (num_vertices) one per surface vertex
  std::vector<Triangle> triangles;       // (num_triangles x 3) as in the surface
  int num_extrapolated = 0;              // vertices outside every hex (extrapolated weights)
  std::string source = "embedded surface";
};

// Embeds mesh in lattice. The lattice must be regular: every hex an axis-aligned box with the same
// edge lengths, its corners on one grid (as MakeBoxHexLattice and VoxelizeSurface build), else
// InputError. A vertex inside a hex's box (closed, with a slack of 1e-9 cell; on a face shared by
// two kept cells the one on the +x/+y/+z side, i.e. floor((X - origin) / h), wins) uses that hex; a
// vertex outside every hex uses the hex whose centre is nearest (ties: lowest index) with
// extrapolated weights. The nearest-hex search is brute force over the hexes,
// O(num_outside_vertices x num_hexes). Throws InputError on an empty lattice or surface or a
// non-finite vertex.
EmbeddedSurface EmbedSurface(const HexLattice& lattice, const SurfaceMesh& mesh);

// Vertex positions x_v = sum_a N_a x_{hex node a} for lattice node positions x (3 num_nodes,
// node-major [x0 y0 z0 x1 ...]). Throws InputError when x has the wrong size or the embedding
// refers to a hex or node the lattice does not have.
std::vector<Vec3> CalcEmbeddedPositions(const EmbeddedSurface& surface, const HexLattice& lattice,
                                        const VecX& x);

// Writes an OBJ file with one "v x y z" line per position (shortest round-trip decimal) and one
// "f a b c" line (1-based) per triangle. Throws InputError on an out-of-range index or when the
// file cannot be written, naming path.
void WriteEmbeddedSurfaceObj(const std::string& path, const std::vector<Vec3>& positions,
                             const std::vector<Triangle>& triangles);

}  // namespace taut
