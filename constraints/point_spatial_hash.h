// Broadphase of the point-triangle contact searches (self-contact and body pairs): a uniform
// spatial hash of points (Teschner et al. 2003, "Optimized spatial hashing for collision detection
// of deformable objects": cells hashed into a table of at least 2 P buckets), rebuilt per search;
// each triangle asks for the points in its bounds grown by the contact margin. O(P + T) per search
// for a well-shaped surface; buffers are reused (no allocation once sized).
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "plugin/common.h"
#include "plugin/tet_mesh.h"

namespace taut {

class PointSpatialHash {
 public:
  // Sorts `points` into cells of size `cell` [m] > 0. `points` must outlive the visits.
  void Build(const std::vector<Vec3>& points, double cell);
  // Calls visit(i) for every point i with lo <= p_i <= hi (componentwise), buckets in cell order;
  // a point may be visited twice (two cells of the box sharing a bucket). A box covering more
  // cells than there are buckets visits every bucket once.
  template <typename Visit>
  void ForEachPointInBox(const Vec3& lo, const Vec3& hi, Visit&& visit) const;

 private:
  // Bucket of cell (ix, iy, iz): (x p1 xor y p2 xor z p3) mod the table size, a power of two.
  std::size_t BucketOf(std::int64_t ix, std::int64_t iy, std::int64_t iz) const;
  // Points of bucket b inside [lo, hi].
  template <typename Visit>
  void VisitBucket(std::size_t b, const Vec3& lo, const Vec3& hi, Visit& visit) const;

  const std::vector<Vec3>* points_ = nullptr;
  std::vector<int> bucket_start_, bucket_points_, bucket_fill_;
  double cell_ = 1.0;
};

// Cell coordinate of a position coordinate (clamped far inside int64 for wild iterates).
std::int64_t CalcHashCell(double coordinate, double cell);

// The cell size of a search with triangles `triangles` whose corner k of triangle t sits at
// corner(t, k): the mean largest extent of the triangles' bounds (each covers a few cells), at
// least `reach` (the margin the bounds grow by).
template <typename CornerPosition>
double CalcHashCellSize(const std::vector<Triangle>& triangles, double reach,
                        CornerPosition&& corner) {
  if (triangles.empty()) return reach;
  double extent = 0.0;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const Vec3 v0 = corner(t, 0), v1 = corner(t, 1), v2 = corner(t, 2);
    extent += (v0.cwiseMax(v1).cwiseMax(v2) - v0.cwiseMin(v1).cwiseMin(v2)).maxCoeff();
  }
  return std::max(reach, extent / static_cast<double>(triangles.size()));
}

template <typename Visit>
void PointSpatialHash::VisitBucket(std::size_t b, const Vec3& lo, const Vec3& hi,
                                   Visit& visit) const {
  for (int k = bucket_start_[b]; k < bucket_start_[b + 1]; ++k) {
    const int i = bucket_points_[k];
    const Vec3& p = (*points_)[i];
    if ((p.array() < lo.array()).any() || (p.array() > hi.array()).any()) continue;
    visit(i);
  }
}

template <typename Visit>
void PointSpatialHash::ForEachPointInBox(const Vec3& lo, const Vec3& hi, Visit&& visit) const {
  if (points_ == nullptr || points_->empty()) return;
  const std::size_t buckets = bucket_start_.size() - 1;
  std::int64_t first[3], last[3];
  double cells = 1.0;
  for (int a = 0; a < 3; ++a) {
    first[a] = CalcHashCell(lo[a], cell_);
    last[a] = CalcHashCell(hi[a], cell_);
    cells *= static_cast<double>(last[a] - first[a] + 1);
  }
  if (cells > static_cast<double>(buckets)) {
    for (std::size_t b = 0; b < buckets; ++b) VisitBucket(b, lo, hi, visit);
    return;
  }
  for (std::int64_t ix = first[0]; ix <= last[0]; ++ix)
    for (std::int64_t iy = first[1]; iy <= last[1]; ++iy)
      for (std::int64_t iz = first[2]; iz <= last[2]; ++iz)
        VisitBucket(BucketOf(ix, iy, iz), lo, hi, visit);
}

}  // namespace taut
