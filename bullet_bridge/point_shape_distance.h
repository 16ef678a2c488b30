// Narrowphase for one deformable surface point against one Bullet collision shape
// (docs/architecture.md §3, stage 3): signed gap, unit normal and closest point on the shape.
//
// Which surface the gap is measured to (one rule: the surface Bullet's own rigid collisions use):
//  - plane, sphere, capsule: the exact analytic surface (for sphere and capsule Bullet's margin is
//    the radius, so this is also the margin surface).
//  - box, cylinder: the user's dimensions, getHalfExtentsWithMargin(), with sharp edges (Bullet
//    subtracts the margin internally and its box-box/box-sphere algorithms use these dimensions).
//  - any other convex shape (btConvexHullShape, cone, multi-sphere, ...): the margin-expanded
//    surface (core points ⊕ ball of getMargin()), from btGjkEpaSolver2::SignedDistance (GJK
//    outside, EPA inside), which is what Bullet's GJK-based convex-convex collision uses.
//  - compound: the nearest child (smallest gap).
//  - concave triangle shapes (btBvhTriangleMeshShape, heightfields): the triangles themselves, no
//    margin. The sign comes from the winding of the nearest triangle (outward = (v1-v0)x(v2-v0)),
//    so for an open mesh it is a one-sided distance: every point behind a triangle counts as
//    penetrating, and points deeper than max_distance behind it are not found (valid = false).
//    Ties at shared edges/vertices go to the triangle most aligned with p − q (not the
//    angle-weighted pseudo-normal), so the sign can be wrong near saddle vertices.
// Why analytic where possible: with margin 0 GJK/EPA matches the analytic sphere, capsule and box
// to ~1e-15 outside and inside (tests/point_shape_distance_test.cc), but costs ~0.9 us per call
// against 20-45 ns, and with Bullet's default box margin it measures to a box with rounded edges
// (up to (√3 − 1)·margin away from the user box at corners).
#pragma once

#include <BulletCollision/CollisionShapes/btCollisionShape.h>
#include <BulletCollision/CollisionShapes/btConvexShape.h>
#include <LinearMath/btTransform.h>

#include "plugin/common.h"

namespace taut {

// Result of a point-vs-shape query.
struct PointContact {
  double gap = 0.0;      // signed distance, < 0 = penetration [m]
  Vec3 normal{0, 0, 0};  // unit, from the rigid shape towards the point (outward when inside)
  Vec3 point_on_shape{0, 0, 0};  // closest point on the shape surface, world
  bool valid = false;  // false: the point is farther than max_distance (other fields unset)
};

// Signed distance from `point` (world) to `shape` placed at `transform`. Returns valid = false
// when the gap exceeds max_distance (early out on the shape's AABB). Throws InputError for a
// negative max_distance or an unsupported shape type (e.g. soft bodies, empty shapes).
PointContact CalcPointShapeDistance(const Vec3& point, const btCollisionShape& shape,
                                    const btTransform& transform, double max_distance);

namespace internal {

// Signed distance to the margin-expanded surface of any convex shape with Bullet's
// btGjkEpaSolver2::SignedDistance (GJK when separated, EPA when penetrating). valid = false only
// if GJK/EPA fails.
PointContact CalcGjkPointDistance(const Vec3& point, const btConvexShape& shape,
                                  const btTransform& transform);

// Closest point to p on triangle (a, b, c) (Voronoi regions of vertices, edges and face).
Vec3 CalcClosestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

}  // namespace internal
}  // namespace taut
