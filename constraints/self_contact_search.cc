#include "constraints/self_contact_search.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "constraints/deformable_contact_source.h"

namespace taut {

namespace {
// Cell coordinate of a position coordinate (clamped far inside int64 for wild iterates).
std::int64_t CellOf(double coordinate, double cell) {
  return static_cast<std::int64_t>(std::clamp(std::floor(coordinate / cell), -1e15, 1e15));
}
}  // namespace

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

std::size_t SelfContactSearch::BucketOf(std::int64_t ix, std::int64_t iy, std::int64_t iz) const {
  // Teschner et al. 2003: (x p1 xor y p2 xor z p3) mod table size, here a power of two.
  const auto mix = (static_cast<std::uint64_t>(ix) * 73856093u) ^
                   (static_cast<std::uint64_t>(iy) * 19349663u) ^
                   (static_cast<std::uint64_t>(iz) * 83492791u);
  return static_cast<std::size_t>(mix & (bucket_start_.size() - 2));
}

void SelfContactSearch::CalcPointPositions(const VecX& x) const {
  positions_.resize(node_of_point_.size());
  for (size_t i = 0; i < node_of_point_.size(); ++i)
    positions_[i] = x.segment<3>(3 * node_of_point_[i]);
}

void SelfContactSearch::BuildHash(double cell) const {
  cell_ = cell;
  const size_t num_points = positions_.size();
  size_t buckets = 1;
  while (buckets < 2 * num_points) buckets <<= 1;
  bucket_start_.assign(buckets + 1, 0);  // BucketOf reads the table size from here
  auto bucket_of = [&](const Vec3& p) {
    return BucketOf(CellOf(p.x(), cell), CellOf(p.y(), cell), CellOf(p.z(), cell));
  };
  for (const Vec3& p : positions_) ++bucket_start_[bucket_of(p) + 1];
  for (size_t b = 0; b < buckets; ++b) bucket_start_[b + 1] += bucket_start_[b];
  bucket_fill_.assign(bucket_start_.begin(), bucket_start_.end() - 1);
  bucket_points_.resize(num_points);
  for (size_t i = 0; i < num_points; ++i)
    bucket_points_[bucket_fill_[bucket_of(positions_[i])]++] = static_cast<int>(i);
}

template <typename Visit>
void SelfContactSearch::ForEachNearPair(const VecX& x, double reach, Visit&& visit) const {
  CalcPointPositions(x);
  if (triangles_.empty() || positions_.empty()) return;
  // Cells about as large as a triangle's bounds: each triangle covers a few cells.
  double extent = 0.0;
  for (const Triangle& t : triangles_) {
    const Vec3 &v0 = positions_[t[0]], &v1 = positions_[t[1]], &v2 = positions_[t[2]];
    extent += (v0.cwiseMax(v1).cwiseMax(v2) - v0.cwiseMin(v1).cwiseMin(v2)).maxCoeff();
  }
  BuildHash(std::max(reach, extent / static_cast<double>(triangles_.size())));
  const size_t buckets = bucket_start_.size() - 1;
  for (size_t t = 0; t < triangles_.size(); ++t) {
    const Triangle& tri = triangles_[t];
    const Vec3 &v0 = positions_[tri[0]], &v1 = positions_[tri[1]], &v2 = positions_[tri[2]];
    const Vec3 lo = v0.cwiseMin(v1).cwiseMin(v2).array() - reach;
    const Vec3 hi = v0.cwiseMax(v1).cwiseMax(v2).array() + reach;
    auto visit_bucket = [&](size_t b) {
      for (int k = bucket_start_[b]; k < bucket_start_[b + 1]; ++k) {
        const int i = bucket_points_[k];
        const Vec3& p = positions_[i];
        if ((p.array() < lo.array()).any() || (p.array() > hi.array()).any()) continue;
        visit(i, static_cast<int>(t), v0, v1, v2);
      }
    };
    std::int64_t first[3], last[3];
    double cells = 1.0;
    for (int a = 0; a < 3; ++a) {
      first[a] = CellOf(lo[a], cell_);
      last[a] = CellOf(hi[a], cell_);
      cells *= static_cast<double>(last[a] - first[a] + 1);
    }
    if (cells > static_cast<double>(buckets)) {
      for (size_t b = 0; b < buckets; ++b) visit_bucket(b);  // a huge triangle: every bucket once
      continue;
    }
    for (std::int64_t ix = first[0]; ix <= last[0]; ++ix)
      for (std::int64_t iy = first[1]; iy <= last[1]; ++iy)
        for (std::int64_t iz = first[2]; iz <= last[2]; ++iz) visit_bucket(BucketOf(ix, iy, iz));
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
