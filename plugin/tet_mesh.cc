#include "plugin/tet_mesh.h"

#include <algorithm>
#include <cmath>
#include <map>

namespace taut {

double CalcTetSignedVolume(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return (a - d).dot((b - d).cross(c - d)) / 6.0;
}

void ValidateTetMesh(const TetMesh& mesh) {
  const std::string& src = mesh.source;
  TAUT_DEMAND(!mesh.nodes.empty(), src, ": mesh has no nodes");
  TAUT_DEMAND(!mesh.tets.empty(), src, ": mesh has no tetrahedra");
  const int n = static_cast<int>(mesh.nodes.size());
  for (int i = 0; i < n; ++i) {
    TAUT_DEMAND(mesh.nodes[i].allFinite(), src, ": node ", i, " has a non-finite coordinate");
  }
  for (size_t e = 0; e < mesh.tets.size(); ++e) {
    const auto& t = mesh.tets[e];
    for (int a = 0; a < 4; ++a) {
      TAUT_DEMAND(t[a] >= 0 && t[a] < n, src, ": element ", e, " refers to node ", t[a],
                  " but the mesh has ", n, " nodes");
      for (int b = 0; b < a; ++b)
        TAUT_DEMAND(t[a] != t[b], src, ": element ", e, " repeats node ", t[a]);
    }
    const Vec3 &x0 = mesh.nodes[t[0]], &x1 = mesh.nodes[t[1]], &x2 = mesh.nodes[t[2]],
               &x3 = mesh.nodes[t[3]];
    const double volume = CalcTetSignedVolume(x0, x1, x2, x3);
    double longest = 0.0;
    const Vec3* p[4] = {&x0, &x1, &x2, &x3};
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < a; ++b) longest = std::max(longest, (*p[a] - *p[b]).norm());
    const double scale = longest * longest * longest;
    TAUT_DEMAND(std::abs(volume) > 1e-12 * scale, src, ": element ", e, " is degenerate (volume ",
                volume, " m^3, longest edge ", longest, " m)");
    TAUT_DEMAND(volume > 0.0, src, ": element ", e, " is inverted (volume ", volume,
                " m^3; expected det[X1-X4, X2-X4, X3-X4] > 0)");
  }
}

std::vector<Triangle> CalcBoundaryFaces(const TetMesh& mesh) {
  // Faces of tet (0,1,2,3) wound outward for positive orientation det[X0-X3, X1-X3, X2-X3] > 0.
  static constexpr int kFaces[4][3] = {{0, 1, 2}, {1, 3, 2}, {0, 2, 3}, {0, 3, 1}};
  std::map<std::array<int, 3>, std::pair<int, Triangle>> count;  // sorted key -> (uses, face)
  for (const auto& t : mesh.tets) {
    for (const auto& f : kFaces) {
      Triangle tri{t[f[0]], t[f[1]], t[f[2]]};
      std::array<int, 3> key = tri;
      std::sort(key.begin(), key.end());
      auto [it, inserted] = count.try_emplace(key, 0, tri);
      it->second.first++;
    }
  }
  std::vector<Triangle> faces;
  for (const auto& [key, entry] : count)
    if (entry.first == 1) faces.push_back(entry.second);
  return faces;
}

std::vector<int> CalcBoundaryNodes(const TetMesh& mesh) {
  std::vector<int> nodes;
  for (const auto& f : CalcBoundaryFaces(mesh)) nodes.insert(nodes.end(), f.begin(), f.end());
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  return nodes;
}

}  // namespace taut
