#include "plugin/contact_surface.h"

#include <algorithm>
#include <map>
#include <tuple>

namespace taut {

namespace {
// One contact point per vertex of an embedded surface: the nodes of the vertex's element
// (ElementOf(vertex) indexes `elements`) with the vertex's weights, x_p = sum_a w_a x_a.
template <typename Element, typename Surface, typename ElementOf>
ContactSurface MakeWeightedPointSurface(const std::vector<Element>& elements,
                                        const Surface& surface, const char* element_name,
                                        ElementOf element_of) {
  ContactSurface result;
  result.node_triangles = false;
  constexpr int kNodes = static_cast<int>(std::tuple_size<Element>::value);
  for (const auto& vertex : surface.vertices) {
    const int e = element_of(vertex);
    TAUT_DEMAND(e >= 0 && e < static_cast<int>(elements.size()), "embedded surface '",
                surface.source, "': ", element_name, " ", e, " out of range");
    ContactPoint p;
    p.num_nodes = kNodes;
    for (int a = 0; a < kNodes; ++a) {
      p.nodes[a] = elements[e][a];
      p.weights[a] = vertex.weights[a];
    }
    result.points.push_back(p);
  }
  result.triangles = surface.triangles;
  return result;
}

// A single-node point.
ContactPoint NodePoint(int node) {
  ContactPoint p;
  p.num_nodes = 1;
  p.nodes[0] = node;
  p.weights[0] = 1.0;
  return p;
}

// Points for the nodes used by `faces` (node triangles), faces renumbered onto them.
ContactSurface MakeNodeSurface(const std::vector<Triangle>& faces) {
  ContactSurface surface;
  std::map<int, int> point_of_node;
  for (const Triangle& face : faces) {
    Triangle t;
    for (int k = 0; k < 3; ++k) {
      auto [it, inserted] =
          point_of_node.try_emplace(face[k], static_cast<int>(point_of_node.size()));
      if (inserted) surface.points.push_back(NodePoint(face[k]));
      t[k] = it->second;
    }
    surface.triangles.push_back(t);
  }
  return surface;
}
}  // namespace

ContactSurface MakeTetContactSurface(const TetMesh& mesh) {
  return MakeNodeSurface(CalcBoundaryFaces(mesh));
}

ContactSurface MakeHexContactSurface(const HexLattice& lattice) {
  // Faces of the local hex (corner a at s_a, a = 4 bi + 2 bj + bk), wound outward (right-handed
  // about the outward normal): -x, +x, -y, +y, -z, +z.
  static constexpr int kFaces[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1},
                                       {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
  std::map<std::array<int, 4>, std::pair<int, std::array<int, 4>>> count;
  for (const auto& hex : lattice.hexes) {
    for (const auto& f : kFaces) {
      const std::array<int, 4> quad{hex[f[0]], hex[f[1]], hex[f[2]], hex[f[3]]};
      std::array<int, 4> key = quad;
      std::sort(key.begin(), key.end());
      auto [it, inserted] = count.try_emplace(key, 0, quad);
      it->second.first++;
    }
  }
  std::vector<Triangle> faces;
  for (const auto& [key, entry] : count) {
    if (entry.first != 1) continue;
    const auto& q = entry.second;
    faces.push_back({q[0], q[1], q[2]});
    faces.push_back({q[0], q[2], q[3]});
  }
  return MakeNodeSurface(faces);
}

ContactSurface MakeEmbeddedContactSurface(const HexLattice& lattice,
                                          const EmbeddedSurface& surface) {
  return MakeWeightedPointSurface(lattice.hexes, surface, "hex",
                                  [](const EmbeddedVertex& vertex) { return vertex.hex; });
}

ContactSurface MakeTetEmbeddedContactSurface(const TetMesh& mesh,
                                             const TetEmbeddedSurface& surface) {
  return MakeWeightedPointSurface(mesh.tets, surface, "tet",
                                  [](const TetEmbeddedVertex& vertex) { return vertex.tet; });
}

ContactSurface MakeEmbeddedBodyContactSurface(const ElementModel& model,
                                              const SurfaceMesh& surface) {
  return model.MakeEmbeddedContactSurface(surface);
}

std::vector<Vec3> CalcContactPointPositions(const ContactSurface& surface, const VecX& x) {
  const int num_nodes = static_cast<int>(x.size() / 3);
  std::vector<Vec3> positions;
  positions.reserve(surface.points.size());
  for (std::size_t i = 0; i < surface.points.size(); ++i) {
    const ContactPoint& p = surface.points[i];
    for (int k = 0; k < p.num_nodes; ++k)
      TAUT_DEMAND(p.nodes[k] >= 0 && p.nodes[k] < num_nodes, "surface point ", i,
                  " refers to node ", p.nodes[k], " but there are ", num_nodes, " node positions");
    positions.push_back(CalcContactPointPosition(p, x));
  }
  return positions;
}

ContactSurface MakeBodyContactSurface(const ElementModel& model) {
  return model.MakeContactSurface();
}

}  // namespace taut
