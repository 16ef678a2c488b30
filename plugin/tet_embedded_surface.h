// A triangle surface embedded in a tet mesh: each vertex follows the mesh through the 4
// barycentric (linear shape function) weights of one tet.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "plugin/surface_mesh.h"
#include "plugin/tet_mesh.h"

namespace taut {

// Where one surface vertex sits in the mesh: its tet and the barycentric weights lambda_a of its
// rest position X in that tet, X = sum_a lambda_a X_a with sum_a lambda_a = 1 (local node order
// of the tet). Inside the tet the weights are in [0, 1] (up to rounding, ~1e-15); for a vertex
// slightly outside the mesh they extrapolate (some negative). Either way x = sum_a lambda_a x_a
// reproduces X at rest and any affine map of the nodes exactly.
struct TetEmbeddedVertex {
  int tet = -1;                     // index into TetMesh::tets
  std::array<double, 4> weights{};  // lambda_a, a = 0..3
  double outside_distance = 0.0;    // distance of X from the tet, 0 inside [m]
};

// A surface carried by a tet mesh.
struct TetEmbeddedSurface {
  std::vector<TetEmbeddedVertex> vertices;  // (num_vertices) one per surface vertex
  std::vector<Triangle> triangles;          // (num_triangles x 3) as in the surface
  int num_extrapolated = 0;                 // vertices outside every tet (extrapolated weights)
  std::string source = "embedded surface";
};

// Embeds `surface` in `mesh` (validated with ValidateTetMesh). A vertex inside a closed tet (every
// lambda_a >= -1e-12) uses the containing tet with the largest smallest weight (on a shared face
// or edge: the tet it is deepest in; ties: lowest index). A vertex outside every tet uses the
// nearest tet (Euclidean distance to the closed tet; ties: largest smallest weight, then lowest
// index) with its extrapolated, not clamped, weights, so the vertex keeps its rest position; it
// must lie within max_outside mean tet edge lengths of the mesh, else InputError naming the vertex
// and its distance. Candidate tets come from a uniform grid over the tets' bounds (grown by the
// tolerance), so the cost is about linear in the vertices plus the tets. Throws InputError on an
// invalid mesh, a surface without vertices, a non-finite vertex, a triangle index out of range or
// max_outside < 0.
TetEmbeddedSurface EmbedSurfaceInTets(const TetMesh& mesh, const SurfaceMesh& surface,
                                      double max_outside = 0.1);

// Vertex positions x_v = sum_a lambda_a x_{tet node a} for mesh node positions x (3 num_nodes,
// node-major [x0 y0 z0 x1 ...]). Throws InputError when x has the wrong size or the embedding
// refers to a tet or node the mesh does not have.
std::vector<Vec3> CalcTetEmbeddedPositions(const TetEmbeddedSurface& surface, const TetMesh& mesh,
                                           const VecX& x);

}  // namespace taut
