// The points and triangles through which a deformable body touches other bodies: boundary
// vertices of tets, boundary corners of hex lattices, or a surface embedded in a hex lattice
// (each point a trilinear combination of its hex's 8 nodes) or in a tet mesh (a barycentric
// combination of its tet's 4 nodes).
#pragma once

#include <array>
#include <vector>

#include "plugin/element_model.h"
#include "plugin/embedded_surface.h"
#include "plugin/hex_lattice.h"
#include "plugin/tet_embedded_surface.h"
#include "plugin/tet_mesh.h"

namespace taut {

// A surface point x_p = sum_k w_k x_{node_k} (weights sum to 1).
struct ContactPoint {
  int num_nodes = 0;
  std::array<int, 8> nodes{};
  std::array<double, 8> weights{};
};

// Contact points and the surface triangles over them (wound outward). `node_triangles` says
// whether every triangle corner is a single node (then a triangle's motion is its 3 nodes'); a
// deformable touching this body's triangles needs that.
struct ContactSurface {
  std::vector<ContactPoint> points;
  std::vector<Triangle> triangles;  // indices into points
  bool node_triangles = true;
};

// Boundary vertices and faces of a tet mesh.
ContactSurface MakeTetContactSurface(const TetMesh& mesh);
// Boundary corners and faces (each boundary quad split in two triangles) of a hex lattice.
ContactSurface MakeHexContactSurface(const HexLattice& lattice);
// The vertices and triangles of a surface embedded in the lattice (8-node points).
ContactSurface MakeEmbeddedContactSurface(const HexLattice& lattice,
                                          const EmbeddedSurface& surface);
// The vertices and triangles of a surface embedded in the tet mesh (4-node points).
ContactSurface MakeTetEmbeddedContactSurface(const TetMesh& mesh,
                                             const TetEmbeddedSurface& surface);
// `surface` (in the rest frame) embedded in a body's model (ElementModel::
// MakeEmbeddedContactSurface: for tets EmbedSurfaceInTets and the function above, for hexes
// EmbedSurface and MakeEmbeddedContactSurface). Throws InputError for a surface that cannot be
// embedded.
ContactSurface MakeEmbeddedBodyContactSurface(const ElementModel& model,
                                              const SurfaceMesh& surface);

// The boundary of a body's model (ElementModel::MakeContactSurface: MakeTetContactSurface or
// MakeHexContactSurface).
ContactSurface MakeBodyContactSurface(const ElementModel& model);

// Position of point p for node positions x (3N).
inline Vec3 CalcContactPointPosition(const ContactPoint& p, const VecX& x) {
  Vec3 sum = Vec3::Zero();
  for (int k = 0; k < p.num_nodes; ++k) sum += p.weights[k] * x.segment<3>(3 * p.nodes[k]);
  return sum;
}

// Positions of every point of `surface` for node positions x (3N), e.g. an embedded surface's
// deformed vertices for a frame. Throws InputError when a point refers to a node x does not have.
std::vector<Vec3> CalcContactPointPositions(const ContactSurface& surface, const VecX& x);

}  // namespace taut
