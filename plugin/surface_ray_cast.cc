#include "plugin/surface_ray_cast.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "plugin/ray_triangle.h"

namespace taut {
namespace internal {

bool SegmentMeetsBox(const Vec3& from, const Vec3& to, const Vec3& lo, const Vec3& hi) {
  // Clip t in [0, 1] by each slab lo_k <= from_k + t d_k <= hi_k.
  const Vec3 d = to - from;
  double t0 = 0.0, t1 = 1.0;
  for (int k = 0; k < 3; ++k) {
    if (d[k] == 0.0) {
      if (from[k] < lo[k] || from[k] > hi[k]) return false;
      continue;
    }
    double ta = (lo[k] - from[k]) / d[k], tb = (hi[k] - from[k]) / d[k];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  return true;
}

}  // namespace internal

namespace {

// Bounds of the points, grown by 1e-9 of their size so hits on flat faces are not clipped.
void CalcPointBounds(const std::vector<Vec3>& points, Vec3& lo, Vec3& hi) {
  lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  hi = -lo;
  for (const Vec3& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double grow = 1e-9 * (hi - lo).norm() + 1e-300;
  lo.array() -= grow;
  hi.array() += grow;
}

// Drops a hit that repeats the previous one (the same crossing through a shared edge or corner).
void MergeSharedEdgeHits(const Vec3& d, std::vector<SurfaceRayHit>& hits) {
  const double length = d.norm();
  std::vector<SurfaceRayHit> merged;
  merged.reserve(hits.size());
  for (const SurfaceRayHit& hit : hits) {
    if (!merged.empty()) {
      const SurfaceRayHit& last = merged.back();
      const bool same_place = (hit.fraction - last.fraction) * length < 1e-12;
      const bool same_side = (hit.normal.dot(d) < 0.0) == (last.normal.dot(d) < 0.0);
      if (same_place && same_side) continue;
    }
    merged.push_back(hit);
  }
  hits.swap(merged);
}

}  // namespace

std::vector<SurfaceRayHit> CastSegmentOnSurface(const ContactSurface& surface,
                                                const std::vector<Vec3>& points, const Vec3& from,
                                                const Vec3& to) {
  TAUT_DEMAND(points.size() == surface.points.size(), "CastSegmentOnSurface: ", points.size(),
              " positions for ", surface.points.size(), " surface points");
  TAUT_DEMAND(from.allFinite() && to.allFinite(), "ray query: the segment (", from.transpose(),
              ") -> (", to.transpose(), ") is not finite");
  std::vector<SurfaceRayHit> hits;
  if (points.empty()) return hits;
  Vec3 lo, hi;
  CalcPointBounds(points, lo, hi);
  if (!internal::SegmentMeetsBox(from, to, lo, hi)) return hits;
  for (std::size_t f = 0; f < surface.triangles.size(); ++f) {
    const Triangle& t = surface.triangles[f];
    const auto hit = IntersectSegmentTriangle(from, to, points[t[0]], points[t[1]], points[t[2]]);
    if (hit) hits.push_back({hit->t, hit->point, hit->normal, static_cast<int>(f)});
  }
  std::stable_sort(hits.begin(), hits.end(), [](const SurfaceRayHit& a, const SurfaceRayHit& b) {
    return a.fraction < b.fraction;
  });
  MergeSharedEdgeHits(to - from, hits);
  return hits;
}

}  // namespace taut
