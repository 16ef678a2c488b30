// A segment against every triangle of a contact surface at given point positions: the crossings
// a ray query reports (bullet_bridge/deformable_queries.h).
#pragma once

#include <vector>

#include "plugin/contact_surface.h"

namespace taut {

// One crossing of the segment with a surface triangle.
struct SurfaceRayHit {
  double fraction = 0.0;  // t of from + t (to - from), in [0, 1] [-]
  Vec3 point{0, 0, 0};    // [m]
  Vec3 normal{0, 0, 0};   // the triangle's outward unit normal; normal . (to - from) < 0 entering
  int triangle = -1;      // index into surface.triangles
};

// Every crossing of the segment from -> to with the triangles of `surface` whose corners are at
// `points` (one position per surface point, CalcContactPointPositions), by increasing fraction.
// A crossing through an edge or corner shared by several triangles is reported once: hits closer
// than 1e-12 m along the segment whose normals face the same side of it are merged (the first
// triangle kept). Nothing when the segment misses the points' bounding box.
std::vector<SurfaceRayHit> CastSegmentOnSurface(const ContactSurface& surface,
                                                const std::vector<Vec3>& points, const Vec3& from,
                                                const Vec3& to);

namespace internal {

// Slab test: does the segment from -> to meet the box [lo, hi]?
bool SegmentMeetsBox(const Vec3& from, const Vec3& to, const Vec3& lo, const Vec3& hi);

}  // namespace internal
}  // namespace taut
