#include "plugin/ray_triangle.h"

#include <cmath>

namespace taut {

std::optional<RayTriangleHit> IntersectSegmentTriangle(const Vec3& from, const Vec3& to,
                                                       const Vec3& a, const Vec3& b,
                                                       const Vec3& c) {
  const Vec3 d = to - from, e1 = b - a, e2 = c - a;
  const Vec3 p = d.cross(e2);
  const double det = e1.dot(p);
  // Parallel (or degenerate): |det| = |d . (e1 x e2)| is tiny against |d| |e1| |e2|.
  if (!(std::abs(det) > 1e-14 * d.norm() * e1.norm() * e2.norm())) return std::nullopt;
  const double inv = 1.0 / det;
  const Vec3 s = from - a;
  RayTriangleHit hit;
  hit.u = s.dot(p) * inv;
  if (hit.u < 0.0 || hit.u > 1.0) return std::nullopt;
  const Vec3 q = s.cross(e1);
  hit.v = d.dot(q) * inv;
  if (hit.v < 0.0 || hit.u + hit.v > 1.0) return std::nullopt;
  hit.t = e2.dot(q) * inv;
  if (hit.t < 0.0 || hit.t > 1.0) return std::nullopt;
  hit.point = from + hit.t * d;
  hit.normal = e1.cross(e2).normalized();
  return hit;
}

}  // namespace taut
