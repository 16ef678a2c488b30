#include "plugin/surface_mesh.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>
#include <utility>

namespace taut {

void ValidateClosedSurface(const SurfaceMesh& mesh) {
  const std::string& src = mesh.source;
  TAUT_DEMAND(!mesh.vertices.empty(), src, ": surface has no vertices");
  TAUT_DEMAND(!mesh.triangles.empty(), src, ": surface has no triangles");
  const int n = static_cast<int>(mesh.vertices.size());
  for (int i = 0; i < n; ++i)
    TAUT_DEMAND(mesh.vertices[i].allFinite(), src, ": vertex ", i, " has a non-finite coordinate");
  // Directed edges (a, b, triangle).
  std::vector<std::tuple<int, int, int>> edges;
  edges.reserve(3 * mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Triangle& tri = mesh.triangles[t];
    for (int a = 0; a < 3; ++a) {
      TAUT_DEMAND(tri[a] >= 0 && tri[a] < n, src, ": triangle ", t, " refers to vertex ", tri[a],
                  " but the surface has ", n, " vertices");
      for (int b = 0; b < a; ++b)
        TAUT_DEMAND(tri[a] != tri[b], src, ": triangle ", t, " repeats vertex ", tri[a]);
    }
    const Vec3& A = mesh.vertices[tri[0]];
    const Vec3& B = mesh.vertices[tri[1]];
    const Vec3& C = mesh.vertices[tri[2]];
    const double longest = std::max({(B - A).norm(), (C - B).norm(), (A - C).norm()});
    const double area2 = (B - A).cross(C - A).norm();
    TAUT_DEMAND(area2 > 1e-12 * longest * longest, src, ": triangle ", t, " (", tri[0], ", ",
                tri[1], ", ", tri[2], ") is degenerate (area ", area2 / 2, " m^2)");
    for (int a = 0; a < 3; ++a) edges.emplace_back(tri[a], tri[(a + 1) % 3], static_cast<int>(t));
  }
  std::sort(edges.begin(), edges.end());
  for (std::size_t i = 0; i < edges.size(); ++i) {
    const auto [a, b, t] = edges[i];
    if (i + 1 < edges.size() && std::get<0>(edges[i + 1]) == a && std::get<1>(edges[i + 1]) == b)
      throw InputError(internal::Concat(
          src, ": edge (", a, ", ", b, ") is used in the same direction by triangles ", t, " and ",
          std::get<2>(edges[i + 1]), " (non-manifold edge or inconsistently oriented triangles)"));
    const auto reverse = std::lower_bound(edges.begin(), edges.end(), std::make_tuple(b, a, -1));
    TAUT_DEMAND(reverse != edges.end() && std::get<0>(*reverse) == b && std::get<1>(*reverse) == a,
                src, ": edge (", a, ", ", b, ") of triangle ", t,
                " has no neighbouring triangle using it as (", b, ", ", a,
                "): the surface is open or inconsistently oriented");
  }
}

Eigen::AlignedBox3d CalcSurfaceBounds(const SurfaceMesh& mesh) {
  TAUT_DEMAND(!mesh.vertices.empty(), mesh.source, ": surface has no vertices");
  Eigen::AlignedBox3d box;
  for (const Vec3& v : mesh.vertices) box.extend(v);
  return box;
}

double CalcSurfaceSignedVolume(const SurfaceMesh& mesh) {
  double six_volume = 0.0;
  for (const Triangle& t : mesh.triangles) {
    const Vec3& a = mesh.vertices[t[0]];
    six_volume += a.dot(mesh.vertices[t[1]].cross(mesh.vertices[t[2]]));
  }
  return six_volume / 6.0;
}

SurfaceMesh MakeCylinderSurface(double length, double radius, int segments, int rings,
                                const Vec3& axis_start) {
  TAUT_DEMAND(length > 0 && radius > 0 && std::isfinite(length) && std::isfinite(radius),
              "cylinder surface: length and radius must be finite and > 0");
  TAUT_DEMAND(segments >= 3 && rings >= 1, "cylinder surface: need >= 3 segments and >= 1 ring");
  SurfaceMesh mesh;
  mesh.source = "cylinder surface";
  // Ring r, segment k -> vertex r * segments + k; then the two cap centres.
  for (int r = 0; r <= rings; ++r)
    for (int k = 0; k < segments; ++k) {
      const double phi = 2.0 * M_PI * k / segments;
      mesh.vertices.push_back(
          axis_start + Vec3(length * r / rings, radius * std::cos(phi), radius * std::sin(phi)));
    }
  const int start_cap = static_cast<int>(mesh.vertices.size());
  mesh.vertices.push_back(axis_start);
  mesh.vertices.push_back(axis_start + Vec3(length, 0, 0));
  auto id = [segments](int r, int k) { return r * segments + (k % segments); };
  for (int r = 0; r < rings; ++r)
    for (int k = 0; k < segments; ++k) {
      // Outward: (x along, then around) gives normal pointing away from the axis.
      mesh.triangles.push_back({id(r, k), id(r, k + 1), id(r + 1, k + 1)});
      mesh.triangles.push_back({id(r, k), id(r + 1, k + 1), id(r + 1, k)});
    }
  for (int k = 0; k < segments; ++k) {
    mesh.triangles.push_back({start_cap, id(0, k + 1), id(0, k)});
    mesh.triangles.push_back({start_cap + 1, id(rings, k), id(rings, k + 1)});
  }
  return mesh;
}

SurfaceMesh MakeBoxSurface(const Vec3& size, int nx, int ny, int nz, const Vec3& min_corner) {
  TAUT_DEMAND(nx > 0 && ny > 0 && nz > 0, "box surface: cell counts must be > 0, got ", nx, "x", ny,
              "x", nz);
  TAUT_DEMAND(size.allFinite() && (size.array() > 0.0).all(),
              "box surface: size must be finite and > 0, got ", size.transpose());
  TAUT_DEMAND(min_corner.allFinite(), "box surface: min corner must be finite");
  SurfaceMesh mesh;
  mesh.source = internal::Concat("box surface ", nx, "x", ny, "x", nz);
  const int counts[3] = {nx, ny, nz};
  std::map<std::array<int, 3>, int> index;  // grid point -> vertex, shared between faces
  auto vertex = [&](const std::array<int, 3>& g) {
    const auto [it, inserted] = index.emplace(g, static_cast<int>(mesh.vertices.size()));
    if (inserted) {
      Vec3 X;
      for (int d = 0; d < 3; ++d) X[d] = min_corner[d] + size[d] * g[d] / counts[d];
      mesh.vertices.push_back(X);
    }
    return it->second;
  };
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;  // (u, v, axis) is right-handed
    for (int side = 0; side < 2; ++side)
      for (int i = 0; i < counts[u]; ++i)
        for (int j = 0; j < counts[v]; ++j) {
          int q[4];  // corners (i, j), (i+1, j), (i+1, j+1), (i, j+1) in the (u, v) plane
          const int di[4] = {0, 1, 1, 0}, dj[4] = {0, 0, 1, 1};
          for (int c = 0; c < 4; ++c) {
            std::array<int, 3> g;
            g[axis] = side * counts[axis];
            g[u] = i + di[c];
            g[v] = j + dj[c];
            q[c] = vertex(g);
          }
          // Counter-clockwise in (u, v) has normal +axis: keep it on the max side, flip on min.
          if (side == 1) {
            mesh.triangles.push_back({q[0], q[1], q[2]});
            mesh.triangles.push_back({q[0], q[2], q[3]});
          } else {
            mesh.triangles.push_back({q[0], q[2], q[1]});
            mesh.triangles.push_back({q[0], q[3], q[2]});
          }
        }
  }
  return mesh;
}

SurfaceMesh MakeIcosphereSurface(double radius, int subdivisions, const Vec3& centre) {
  TAUT_DEMAND(std::isfinite(radius) && radius > 0.0,
              "icosphere: radius must be finite and > 0, got ", radius);
  TAUT_DEMAND(subdivisions >= 0 && subdivisions <= 7,
              "icosphere: subdivisions must be in [0, 7], got ", subdivisions);
  TAUT_DEMAND(centre.allFinite(), "icosphere: centre must be finite");
  const double p = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec3> unit = {{-1, p, 0}, {1, p, 0}, {-1, -p, 0}, {1, -p, 0},
                            {0, -1, p}, {0, 1, p}, {0, -1, -p}, {0, 1, -p},
                            {p, 0, -1}, {p, 0, 1}, {-p, 0, -1}, {-p, 0, 1}};
  for (Vec3& v : unit) v.normalize();
  std::vector<Triangle> tris = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int level = 0; level < subdivisions; ++level) {
    std::map<std::pair<int, int>, int> midpoint;  // edge (min, max) -> new vertex
    auto mid = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      const auto [it, inserted] = midpoint.emplace(key, static_cast<int>(unit.size()));
      if (inserted) unit.push_back((unit[a] + unit[b]).normalized());
      return it->second;
    };
    std::vector<Triangle> finer;
    finer.reserve(4 * tris.size());
    for (const Triangle& t : tris) {
      const int ab = mid(t[0], t[1]), bc = mid(t[1], t[2]), ca = mid(t[2], t[0]);
      finer.push_back({t[0], ab, ca});
      finer.push_back({t[1], bc, ab});
      finer.push_back({t[2], ca, bc});
      finer.push_back({ab, bc, ca});
    }
    tris = std::move(finer);
  }
  SurfaceMesh mesh;
  mesh.source = internal::Concat("icosphere r=", radius, " level ", subdivisions);
  mesh.vertices.reserve(unit.size());
  for (const Vec3& v : unit) mesh.vertices.push_back(centre + radius * v);
  mesh.triangles = std::move(tris);
  return mesh;
}

}  // namespace taut
