// One segment against one triangle (Möller–Trumbore), for ray queries on deformable surfaces.
#pragma once

#include <optional>

#include "plugin/common.h"

namespace taut {

// Where the segment from + t (to - from), t in [0, 1], crosses triangle (a, b, c).
struct RayTriangleHit {
  double t = 0.0;        // fraction along the segment [-]
  double u = 0.0;        // barycentric weight of b [-]
  double v = 0.0;        // barycentric weight of c [-]; point = (1-u-v) a + u b + v c
  Vec3 point{0, 0, 0};   // from + t (to - from) [m]
  Vec3 normal{0, 0, 0};  // unit (b - a) x (c - a): outward for a triangle wound outward [-]
};

// Möller–Trumbore: with d = to - from, e1 = b - a, e2 = c - a, s = from - a, p = d x e2,
// q = s x e1 and det = e1 . p, the crossing is u = s.p/det, v = d.q/det, t = e2.q/det, a hit
// when u >= 0, v >= 0, u + v <= 1 and 0 <= t <= 1. Both sides count (entering and leaving);
// edges and corners are inclusive. No hit for a segment parallel to the triangle's plane
// (|det| <= 1e-14 |d| |e1| |e2|) or a degenerate triangle.
std::optional<RayTriangleHit> IntersectSegmentTriangle(const Vec3& from, const Vec3& to,
                                                       const Vec3& a, const Vec3& b, const Vec3& c);

}  // namespace taut
