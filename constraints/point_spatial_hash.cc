#include "constraints/point_spatial_hash.h"

#include <algorithm>
#include <cmath>

namespace taut {

std::int64_t CalcHashCell(double coordinate, double cell) {
  return static_cast<std::int64_t>(std::clamp(std::floor(coordinate / cell), -1e15, 1e15));
}

std::size_t PointSpatialHash::BucketOf(std::int64_t ix, std::int64_t iy, std::int64_t iz) const {
  const auto mix = (static_cast<std::uint64_t>(ix) * 73856093u) ^
                   (static_cast<std::uint64_t>(iy) * 19349663u) ^
                   (static_cast<std::uint64_t>(iz) * 83492791u);
  return static_cast<std::size_t>(mix & (bucket_start_.size() - 2));
}

void PointSpatialHash::Build(const std::vector<Vec3>& points, double cell) {
  points_ = &points;
  cell_ = cell;
  const std::size_t num_points = points.size();
  std::size_t buckets = 1;
  while (buckets < 2 * num_points) buckets <<= 1;
  bucket_start_.assign(buckets + 1, 0);  // BucketOf reads the table size from here
  auto bucket_of = [&](const Vec3& p) {
    return BucketOf(CalcHashCell(p.x(), cell), CalcHashCell(p.y(), cell),
                    CalcHashCell(p.z(), cell));
  };
  for (const Vec3& p : points) ++bucket_start_[bucket_of(p) + 1];
  for (std::size_t b = 0; b < buckets; ++b) bucket_start_[b + 1] += bucket_start_[b];
  bucket_fill_.assign(bucket_start_.begin(), bucket_start_.end() - 1);
  bucket_points_.resize(num_points);
  for (std::size_t i = 0; i < num_points; ++i)
    bucket_points_[bucket_fill_[bucket_of(points[i])]++] = static_cast<int>(i);
}

}  // namespace taut
