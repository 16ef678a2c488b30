#include "plugin/tet_embedded_surface.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "plugin/box_grid.h"

namespace taut {
namespace {

// A vertex is inside a tet when every barycentric weight is >= -kInsideSlack (rounding).
constexpr double kInsideSlack = 1e-12;
constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Barycentric frame of a rest tet: (lambda_0, lambda_1, lambda_2) = D^-1 (X - X_3) with
// D = [X_0 - X_3, X_1 - X_3, X_2 - X_3], and lambda_3 = 1 - lambda_0 - lambda_1 - lambda_2.
struct TetFrame {
  Mat3 inverse;
  Vec3 origin;  // X_3
};

TetFrame MakeTetFrame(const TetMesh& mesh, int tet) {
  const auto& t = mesh.tets[tet];
  const Vec3& X3 = mesh.nodes[t[3]];
  Mat3 D;
  D << mesh.nodes[t[0]] - X3, mesh.nodes[t[1]] - X3, mesh.nodes[t[2]] - X3;
  return {D.inverse(), X3};
}

std::array<double, 4> CalcBarycentricWeights(const TetFrame& frame, const Vec3& X) {
  const Vec3 l = frame.inverse * (X - frame.origin);
  return {l[0], l[1], l[2], 1.0 - l[0] - l[1] - l[2]};
}

// Distance from p to the closed triangle (a, b, c): the nearest point by its Voronoi region
// (vertex, edge or face; Ericson, Real-Time Collision Detection, 5.1.5).
double CalcPointTriangleDistance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a, bp = p - b, cp = p - c;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return ap.norm();
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return bp.norm();
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return (ap - d1 / (d1 - d3) * ab).norm();
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return cp.norm();
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return (ap - d2 / (d2 - d6) * ac).norm();
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && d4 >= d3 && d5 >= d6)
    return (bp - (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b)).norm();
  return (ap - (vb * ab + vc * ac) / (va + vb + vc)).norm();
}

// Distance from X to the closed tet with weights w at X: 0 inside, else the distance to the
// nearest face whose plane X is outside of (lambda_a < 0: the face opposite node a).
double CalcPointTetDistance(const TetMesh& mesh, int tet, const std::array<double, 4>& w,
                            const Vec3& X) {
  static constexpr int kOpposite[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
  const auto& t = mesh.tets[tet];
  double distance = kInfinity;
  for (int a = 0; a < 4; ++a) {
    if (w[a] >= 0.0) continue;
    const auto& f = kOpposite[a];
    distance =
        std::min(distance, CalcPointTriangleDistance(X, mesh.nodes[t[f[0]]], mesh.nodes[t[f[1]]],
                                                     mesh.nodes[t[f[2]]]));
  }
  return distance == kInfinity ? 0.0 : distance;
}

// A tet holding (or nearest to) a vertex.
struct Placement {
  int tet = -1;
  std::array<double, 4> weights{};
  double distance = kInfinity;     // 0 inside
  double min_weight = -kInfinity;  // smallest lambda_a
};

// Nearer wins, then the larger smallest weight; on a full tie the earlier (lower index) stays.
bool IsBetter(const Placement& candidate, const Placement& best) {
  if (candidate.distance != best.distance) return candidate.distance < best.distance;
  return candidate.min_weight > best.min_weight;
}

// The best placement of X among `tets`: containing tets first; the distances of the others are
// computed only when no tet contains X.
template <typename TetRange>
Placement PlaceVertex(const TetMesh& mesh, const std::vector<TetFrame>& frames,
                      const TetRange& tets, const Vec3& X) {
  Placement best;
  for (int pass = 0; pass < 2 && best.distance > 0.0; ++pass) {
    for (const int tet : tets) {
      Placement candidate;
      candidate.tet = tet;
      candidate.weights = CalcBarycentricWeights(frames[tet], X);
      candidate.min_weight = *std::min_element(candidate.weights.begin(), candidate.weights.end());
      const bool inside = candidate.min_weight >= -kInsideSlack;
      if (pass == 0 && !inside) continue;
      candidate.distance = inside ? 0.0 : CalcPointTetDistance(mesh, tet, candidate.weights, X);
      if (IsBetter(candidate, best)) best = candidate;
    }
  }
  return best;
}

// Mean length of the 6 edges of every tet [m].
double CalcMeanTetEdgeLength(const TetMesh& mesh) {
  double sum = 0.0;
  for (const auto& t : mesh.tets)
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) sum += (mesh.nodes[t[a]] - mesh.nodes[t[b]]).norm();
  return sum / (6.0 * static_cast<double>(mesh.tets.size()));
}

// Rest bounds of every tet, grown by `margin` on each side.
std::vector<Eigen::AlignedBox3d> CalcTetBounds(const TetMesh& mesh, double margin) {
  std::vector<Eigen::AlignedBox3d> bounds(mesh.tets.size());
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) {
    for (int n : mesh.tets[e]) bounds[e].extend(mesh.nodes[n]);
    bounds[e].min().array() -= margin;
    bounds[e].max().array() += margin;
  }
  return bounds;
}

// Checks the surface's vertices and triangle indices.
void ValidateSurfaceToEmbed(const SurfaceMesh& surface) {
  TAUT_DEMAND(!surface.vertices.empty(), surface.source,
              ": cannot embed a surface without vertices");
  for (std::size_t v = 0; v < surface.vertices.size(); ++v)
    TAUT_DEMAND(surface.vertices[v].allFinite(), surface.source, ": vertex ", v,
                " has a non-finite coordinate");
  const int num_vertices = static_cast<int>(surface.vertices.size());
  for (std::size_t t = 0; t < surface.triangles.size(); ++t)
    for (int i : surface.triangles[t])
      TAUT_DEMAND(i >= 0 && i < num_vertices, surface.source, ": triangle ", t,
                  " refers to vertex ", i, " but there are ", num_vertices);
}

// Throws the error for vertex v, farther than `tolerance` [m] outside every tet: brute force
// over the tets for its distance to the mesh.
[[noreturn]] void ThrowVertexOutside(const TetMesh& mesh, const std::vector<TetFrame>& frames,
                                     const SurfaceMesh& surface, std::size_t v, double max_outside,
                                     double tolerance) {
  std::vector<int> all(mesh.tets.size());
  for (std::size_t e = 0; e < all.size(); ++e) all[e] = static_cast<int>(e);
  const Vec3& X = surface.vertices[v];
  const Placement nearest = PlaceVertex(mesh, frames, all, X);
  throw InputError(internal::Concat(
      surface.source, ": vertex ", v, " at (", X.x(), ", ", X.y(), ", ", X.z(), ") is ",
      nearest.distance, " m outside tet mesh '", mesh.source, "' (nearest tet ", nearest.tet,
      "); at most ", max_outside, " mean tet edge lengths = ", tolerance, " m are allowed"));
}

}  // namespace

TetEmbeddedSurface EmbedSurfaceInTets(const TetMesh& mesh, const SurfaceMesh& surface,
                                      double max_outside) {
  ValidateTetMesh(mesh);
  ValidateSurfaceToEmbed(surface);
  TAUT_DEMAND(std::isfinite(max_outside) && max_outside >= 0.0, surface.source,
              ": the tolerance outside the tet mesh must be finite and >= 0 edge lengths, got ",
              max_outside);
  const double edge = CalcMeanTetEdgeLength(mesh);
  const double tolerance = max_outside * edge;
  std::vector<TetFrame> frames(mesh.tets.size());
  for (std::size_t e = 0; e < frames.size(); ++e)
    frames[e] = MakeTetFrame(mesh, static_cast<int>(e));
  // Every tet within `tolerance` of X has X in its grown bounds (plus a rounding slack), so it is
  // among the candidates of X's cell.
  const BoxGrid grid(CalcTetBounds(mesh, tolerance + 1e-9 * edge));
  TetEmbeddedSurface out;
  out.source = surface.source;
  out.triangles = surface.triangles;
  out.vertices.resize(surface.vertices.size());
  for (std::size_t v = 0; v < surface.vertices.size(); ++v) {
    const Placement placement =
        PlaceVertex(mesh, frames, grid.FindCandidates(surface.vertices[v]), surface.vertices[v]);
    if (placement.tet < 0 || placement.distance > tolerance)
      ThrowVertexOutside(mesh, frames, surface, v, max_outside, tolerance);
    out.vertices[v] = {placement.tet, placement.weights, placement.distance};
    out.num_extrapolated += placement.distance > 0.0;
  }
  return out;
}

std::vector<Vec3> CalcTetEmbeddedPositions(const TetEmbeddedSurface& surface, const TetMesh& mesh,
                                           const VecX& x) {
  const std::size_t num_nodes = mesh.nodes.size();
  TAUT_DEMAND(static_cast<std::size_t>(x.size()) == 3 * num_nodes, surface.source,
              ": node positions have ", x.size(), " entries, expected 3 x ", num_nodes);
  std::vector<Vec3> positions(surface.vertices.size(), Vec3::Zero());
  for (std::size_t v = 0; v < surface.vertices.size(); ++v) {
    const TetEmbeddedVertex& ev = surface.vertices[v];
    TAUT_DEMAND(ev.tet >= 0 && static_cast<std::size_t>(ev.tet) < mesh.tets.size(), surface.source,
                ": vertex ", v, " refers to tet ", ev.tet, " but ", mesh.source, " has ",
                mesh.tets.size());
    for (int a = 0; a < 4; ++a) {
      const int n = mesh.tets[ev.tet][a];
      TAUT_DEMAND(n >= 0 && static_cast<std::size_t>(n) < num_nodes, mesh.source, ": element ",
                  ev.tet, " refers to node ", n);
      positions[v] += ev.weights[a] * x.segment<3>(3 * n);
    }
  }
  return positions;
}

}  // namespace taut
