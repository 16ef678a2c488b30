#include "plugin/finger_mesher.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace taut {

namespace {
// Closest point of segment [a, b] to p.
Vec3 CalcClosestSegmentPoint(const Vec3& a, const Vec3& b, const Vec3& p) {
  const Vec3 ab = b - a;
  const double length2 = ab.squaredNorm();
  if (length2 == 0.0) return a;
  return a + std::clamp((p - a).dot(ab) / length2, 0.0, 1.0) * ab;
}

// Throws unless every capsule is finite with a positive radius.
void ValidateCapsules(const std::vector<Capsule>& capsules) {
  TAUT_DEMAND(!capsules.empty(), "capsule union mesh: no capsules");
  for (size_t i = 0; i < capsules.size(); ++i) {
    const Capsule& c = capsules[i];
    TAUT_DEMAND(c.a.allFinite() && c.b.allFinite(), "capsule union mesh: capsule ", i,
                " has a non-finite end point");
    TAUT_DEMAND(std::isfinite(c.radius) && c.radius > 0.0, "capsule union mesh: capsule ", i,
                " radius ", c.radius, " must be finite and > 0");
  }
}

// Moves p onto the union's surface along the distance gradient (a few fixed-point rounds: a step
// onto one capsule can land inside a neighbour at a junction).
Vec3 ProjectOntoSurface(const std::vector<Capsule>& capsules, Vec3 p, double scale) {
  for (int round = 0; round < 20; ++round) {
    Vec3 gradient;
    const double phi = CalcCapsuleUnionDistance(capsules, p, &gradient);
    if (std::abs(phi) <= 1e-12 * scale) break;
    p -= phi * gradient;
  }
  return p;
}
}  // namespace

double CalcCapsuleUnionDistance(const std::vector<Capsule>& capsules, const Vec3& p,
                                Vec3* gradient) {
  double best = std::numeric_limits<double>::infinity();
  for (const Capsule& c : capsules) {
    const Vec3 q = CalcClosestSegmentPoint(c.a, c.b, p);
    const double phi = (p - q).norm() - c.radius;
    if (phi >= best) continue;
    best = phi;
    if (gradient == nullptr) continue;
    // On the axis itself any direction orthogonal to the segment is steepest; pick one.
    const Vec3 d = p - q;
    if (d.norm() > 0.0) {
      *gradient = d.normalized();
    } else {
      const Vec3 axis = c.b - c.a;
      *gradient = axis.norm() > 0.0 ? axis.unitOrthogonal() : Vec3::UnitX();
    }
  }
  return best;
}

TetMesh MakeCapsuleUnionTetMesh(const std::vector<Capsule>& capsules,
                                const CapsuleMeshSettings& settings) {
  ValidateCapsules(capsules);
  TAUT_DEMAND(settings.cell_size.allFinite() && (settings.cell_size.array() > 0.0).all(),
              "capsule union mesh: cell size ", settings.cell_size.transpose(),
              " must be finite and > 0");
  TAUT_DEMAND(settings.keep_offset >= 0.0 && settings.keep_offset <= 1.0,
              "capsule union mesh: keep_offset ", settings.keep_offset, " must be in [0, 1]");
  // Grid over the bounding box of the union.
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Capsule& c : capsules) {
    lo = lo.cwiseMin(c.a.cwiseMin(c.b) - Vec3::Constant(c.radius));
    hi = hi.cwiseMax(c.a.cwiseMax(c.b) + Vec3::Constant(c.radius));
  }
  int n[3];
  Vec3 cell;
  for (int axis = 0; axis < 3; ++axis) {
    const double extent = hi[axis] - lo[axis];
    n[axis] = std::max(1, static_cast<int>(std::lround(extent / settings.cell_size[axis])));
    cell[axis] = extent / n[axis];
  }
  // Keep the cells whose centre is inside the (slightly inflated) union.
  const double keep = settings.keep_offset * cell.minCoeff();
  std::vector<std::array<int, 3>> kept;
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        const Vec3 centre = lo + Vec3(i + 0.5, j + 0.5, k + 0.5).cwiseProduct(cell);
        if (CalcCapsuleUnionDistance(capsules, centre) < keep) kept.push_back({i, j, k});
      }
  TAUT_DEMAND(!kept.empty(), "capsule union mesh: no cell centre lies inside the capsules ",
              "(cell size ", settings.cell_size.transpose(), " too large?)");
  // Grid nodes of the kept cells, numbered in grid order (x fastest).
  const int px = n[0] + 1, py = n[1] + 1;
  auto grid_node = [&](int i, int j, int k) { return i + px * (j + py * k); };
  std::vector<int> index(static_cast<size_t>(px) * py * (n[2] + 1), -1);
  for (const auto& c : kept)
    for (int corner = 0; corner < 8; ++corner)
      index[grid_node(c[0] + (corner & 1), c[1] + ((corner >> 1) & 1), c[2] + (corner >> 2))] = 0;
  TetMesh mesh;
  mesh.source = internal::Concat("capsule union ", n[0], "x", n[1], "x", n[2]);
  for (int k = 0; k <= n[2]; ++k)
    for (int j = 0; j <= n[1]; ++j)
      for (int i = 0; i <= n[0]; ++i) {
        int& id = index[grid_node(i, j, k)];
        if (id < 0) continue;
        id = static_cast<int>(mesh.nodes.size());
        mesh.nodes.push_back(lo + Vec3(i, j, k).cwiseProduct(cell));
      }
  // Kuhn split: one tet per axis permutation, walking 000 -> 111 one axis at a time.
  static constexpr int kPerms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                       {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (const auto& c : kept)
    for (const auto& perm : kPerms) {
      int g[3] = {c[0], c[1], c[2]};
      std::array<int, 4> tet;
      tet[0] = index[grid_node(g[0], g[1], g[2])];
      for (int step = 0; step < 3; ++step) {
        g[perm[step]]++;
        tet[step + 1] = index[grid_node(g[0], g[1], g[2])];
      }
      const auto& X = mesh.nodes;
      if (CalcTetSignedVolume(X[tet[0]], X[tet[1]], X[tet[2]], X[tet[3]]) < 0.0)
        std::swap(tet[0], tet[1]);
      mesh.tets.push_back(tet);
    }
  ValidateTetMesh(mesh);
  if (settings.snap_boundary) {
    const double scale = (hi - lo).norm();
    for (int node : CalcBoundaryNodes(mesh))
      mesh.nodes[node] = ProjectOntoSurface(capsules, mesh.nodes[node], scale);
    try {
      ValidateTetMesh(mesh);
    } catch (const InputError& error) {
      throw InputError(std::string(error.what()) +
                       " after snapping the boundary onto the capsules (use smaller cells or "
                       "snap_boundary = false)");
    }
  }
  return mesh;
}

std::vector<Capsule> MakeFingerCapsules(double length) {
  TAUT_DEMAND(std::isfinite(length) && length > 0.0, "finger: length ", length,
              " must be finite and > 0");
  const double scale = length / 0.07;
  const double radius[3] = {0.009 * scale, 0.0085 * scale, 0.008 * scale};
  // Segments between the proximal cap (radius[0]) and the tip cap (radius[2]), split 35:25:18.
  const double start = radius[0], span = length - radius[0] - radius[2];
  const double split[4] = {0.0, 35.0 / 78.0, 60.0 / 78.0, 1.0};
  std::vector<Capsule> capsules(3);
  for (int i = 0; i < 3; ++i) {
    capsules[i].a = Vec3(start + split[i] * span, 0.0, 0.0);
    capsules[i].b = Vec3(start + split[i + 1] * span, 0.0, 0.0);
    capsules[i].radius = radius[i];
  }
  return capsules;
}

}  // namespace taut
