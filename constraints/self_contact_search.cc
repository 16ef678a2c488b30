#include "constraints/self_contact_search.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "constraints/deformable_contact_source.h"

namespace taut {

SelfContactSearch::SelfContactSearch(const DeformableBody& body, const ContactSurface& surface,
                                     double margin)
    : body_(body), triangles_(surface.triangles), margin_(margin) {
  TAUT_DEMAND(std::isfinite(margin) && margin > 0.0, "body '", body.name(),
              "': self-contact margin must be finite and > 0 m, got ", margin);
  TAUT_DEMAND(surface.node_triangles, "body '", body.name(),
              "': self-contact needs a surface of node triangles (the body's boundary)");
  for (const ContactPoint& point : surface.points) {
    TAUT_DEMAND(point.num_nodes == 1 && point.nodes[0] >= 0 && point.nodes[0] < body.num_nodes(),
                "body '", body.name(), "': self-contact points must be single nodes of the body");
    node_of_point_.push_back(point.nodes[0]);
  }
  const int num_points = static_cast<int>(node_of_point_.size());
  for (const Triangle& t : triangles_)
    for (int corner : t)
      TAUT_DEMAND(corner >= 0 && corner < num_points, "body '", body.name(),
                  "': self-contact triangle corner ", corner, " out of range [0, ", num_points,
                  ")");
  FindExcludedPairs(body.model().rest_positions());
}

void SelfContactSearch::CalcPointPositions(const VecX& x) const {
  positions_.resize(node_of_point_.size());
  for (size_t i = 0; i < node_of_point_.size(); ++i)
    positions_[i] = x.segment<3>(3 * node_of_point_[i]);
}

template <typename Visit>
void SelfContactSearch::ForEachNearPair(const VecX& x, double reach, Visit&& visit) const {
  CalcPointPositions(x);
  if (triangles_.empty() || positions_.empty()) return;
  hash_.Build(positions_, CalcHashCellSize(triangles_, reach, [&](std::size_t t, int k) {
                return positions_[triangles_[t][k]];
              }));
  for (size_t t = 0; t < triangles_.size(); ++t) {
    const Triangle& tri = triangles_[t];
    const Vec3 &v0 = positions_[tri[0]], &v1 = positions_[tri[1]], &v2 = positions_[tri[2]];
    const Vec3 lo = v0.cwiseMin(v1).cwiseMin(v2).array() - reach;
    const Vec3 hi = v0.cwiseMax(v1).cwiseMax(v2).array() + reach;
    hash_.ForEachPointInBox(lo, hi, [&](int i) { visit(i, static_cast<int>(t), v0, v1, v2); });
  }
}

void SelfContactSearch::FindExcludedPairs(const VecX& rest) {
  const double radius = kRestExclusion * margin_;
  std::vector<std::pair<int, int>> pairs;
  ForEachNearPair(rest, radius, [&](int i, int t, const Vec3& v0, const Vec3& v1, const Vec3& v2) {
    const Vec3& p = positions_[i];
    const Vec3 beta = internal::CalcNearestTrianglePoint(p, v0, v1, v2);
    const Vec3 q = beta[0] * v0 + beta[1] * v1 + beta[2] * v2;
    if ((p - q).norm() < radius) pairs.emplace_back(i, t);
  });
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  excluded_start_.assign(node_of_point_.size() + 1, 0);
  excluded_.clear();
  for (const auto& [i, t] : pairs) {
    ++excluded_start_[i + 1];
    excluded_.push_back(t);
  }
  for (size_t i = 0; i < node_of_point_.size(); ++i) excluded_start_[i + 1] += excluded_start_[i];
}

bool SelfContactSearch::IsExcluded(int i, int t) const {
  const auto begin = excluded_.begin() + excluded_start_[i];
  const auto end = excluded_.begin() + excluded_start_[i + 1];
  return std::binary_search(begin, end, t);
}

void SelfContactSearch::CalcPointNormals(const VecX& x) const {
  // n_i = sum over the triangles around i of (x_1 - x_0) x (x_2 - x_0) (twice the area times the
  // unit normal).
  point_normals_.assign(node_of_point_.size(), Vec3::Zero());
  for (const Triangle& t : triangles_) {
    const Vec3 v0 = x.segment<3>(3 * node_of_point_[t[0]]);
    const Vec3 v1 = x.segment<3>(3 * node_of_point_[t[1]]);
    const Vec3 v2 = x.segment<3>(3 * node_of_point_[t[2]]);
    const Vec3 area_normal = (v1 - v0).cross(v2 - v0);
    for (int corner : t) point_normals_[corner] += area_normal;
  }
}

bool SelfContactSearch::Moves(int i, int t) const {
  if (body_.node_kind(node_of_point_[i]) == NodeKind::kFree) return true;
  for (int corner : triangles_[t])
    if (body_.node_kind(node_of_point_[corner]) == NodeKind::kFree) return true;
  return false;
}

void SelfContactSearch::FindHits(const VecX& x, std::vector<Hit>& hits) const {
  CalcPointNormals(x);
  const Hit none{-1, -1, Vec3::Zero(), Vec3::Zero(), 0.0};
  best_.assign(node_of_point_.size(), none);
  best_distance_.assign(node_of_point_.size(), margin_);
  ForEachNearPair(x, margin_, [&](int i, int t, const Vec3& v0, const Vec3& v1, const Vec3& v2) {
    const Vec3 normal = (v1 - v0).cross(v2 - v0);
    if (normal.squaredNorm() == 0.0) return;           // degenerate triangle
    if (point_normals_[i].dot(normal) >= 0.0) return;  // not facing each other
    if (IsExcluded(i, t) || !Moves(i, t)) return;
    const Vec3& p = positions_[i];
    const Vec3 beta = internal::CalcNearestTrianglePoint(p, v0, v1, v2);
    const Vec3 q = beta[0] * v0 + beta[1] * v1 + beta[2] * v2;
    const double distance = (p - q).norm();
    if (distance >= best_distance_[i]) return;  // first the margin, then the nearest so far
    best_distance_[i] = distance;
    Hit& best = best_[i];
    best = {i, t, normal.normalized(), beta, 0.0};
    best.gap = best.normal.dot(p - q);
  });
  hits.clear();
  for (const Hit& hit : best_)
    if (hit.triangle >= 0) hits.push_back(hit);
}

}  // namespace taut
