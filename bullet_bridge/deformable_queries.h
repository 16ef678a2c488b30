// Queries Bullet users make of a scene, answered for taut's deformable bodies: ray tests and
// contact tests against their current contact surfaces, with Bullet's collision groups and masks.
//
// A deformable's btCollisionObject (bullet_bridge/deformable_collision_object.h) only reports a
// bounding box, so btCollisionWorld::rayTest and contactTest pass over it. These functions test
// the surface taut contacts with (plugin/contact_surface.h) at the current node positions x, so
// they follow the body as it deforms; they change nothing in the simulation. Surface used today:
// the boundary of each body's model (MakeBodyContactSurface, rebuilt per call, O(elements)); a
// surface given to DeformableWorld::SetContactSurface is not seen by the world-level functions
// (the world does not expose it), pass it to RayTestDeformable / ContactTestDeformable instead.
#pragma once

#include <BulletCollision/CollisionDispatch/btCollisionWorld.h>

#include <optional>
#include <vector>

#include "bullet_bridge/collision_filter.h"
#include "bullet_bridge/deformable_world.h"
#include "plugin/contact_surface.h"

namespace taut {

// One crossing of a ray with a deformable's surface triangle. World coordinates.
struct DeformableRayHit {
  const DeformableBody* body = nullptr;
  const btCollisionObject* object = nullptr;  // the body's collision object in the world
  double fraction = 0.0;                      // t of from + t (to - from), in [0, 1] [-]
  Vec3 point = Vec3::Zero();                  // from + t (to - from) [m]
  // Outward unit normal of the triangle [-]; normal . (to - from) < 0 where the ray enters.
  Vec3 normal = Vec3::Zero();
  int triangle = -1;  // index into the contact surface's triangles
  // The element holding the hit: the boundary face's own element, or for embedded surfaces the
  // tet containing the point, else the nearest candidate (plugin/surface_hit_element.h).
  int element = -1;
};

// One surface point of a deformable near or inside a rigid object. World coordinates.
struct DeformableContactHit {
  const DeformableBody* body = nullptr;
  const btCollisionObject* object = nullptr;  // the body's collision object in the world
  int point = -1;                             // index into the contact surface's points
  int node = -1;                              // the node when the point is a single node, else -1
  Vec3 position = Vec3::Zero();               // the surface point [m]
  Vec3 normal = Vec3::Zero();                 // unit, from the rigid shape towards the point [-]
  Vec3 point_on_shape = Vec3::Zero();         // closest point on the rigid shape's surface [m]
  // Penetration depth -gap [m]: > 0 inside the shape, in [-max_gap, 0] just outside (the gap is
  // measured to the surface bullet_bridge/point_shape_distance.h names for the shape type).
  double depth = 0.0;
};

// The closest crossing of the segment from -> to [m] with any deformable's surface (entering or
// leaving), among the bodies `filter` sees (PassesQueryFilter: Bullet's RayResultCallback rule);
// nothing when it misses. Throws InputError for a non-finite segment.
std::optional<DeformableRayHit> RayTestDeformables(const DeformableWorld& world,
                                                   const btVector3& from, const btVector3& to,
                                                   const QueryFilter& filter = {});
// Every crossing (each body's entries and exits), by increasing fraction.
std::vector<DeformableRayHit> RayTestAllDeformables(const DeformableWorld& world,
                                                    const btVector3& from, const btVector3& to,
                                                    const QueryFilter& filter = {});
// Bullet-style: reports each crossing to `callback` (its group, mask and needsCollision decide
// which bodies it sees; only hits with fraction <= m_closestHitFraction are passed), as a
// LocalRayResult with the body's collision object, m_triangleIndex = triangle, normal in world
// coordinates. Call it after world.rayTest(from, to, callback) and a ClosestRayResultCallback
// holds the closest hit of rigid and deformable objects alike.
void RayTestDeformables(const DeformableWorld& world, const btVector3& from, const btVector3& to,
                        btCollisionWorld::RayResultCallback& callback);

// The surface points of every deformable within `max_gap` [m] (>= 0; 0: touching or inside) of
// `rigid` at its current transform, by body then point. Groups and masks: `filter` when given,
// else the rigid object's own (its broadphase proxy's, which a contact pair would use; every
// body when it is not in a world). Convex hulls are measured by GJK/EPA unless their face planes
// exist (initializePolyhedralFeatures; the world makes them once a deformable comes near).
// Throws InputError for a negative max_gap or a shape point_shape_distance does not support.
std::vector<DeformableContactHit> ContactTestDeformables(
    const DeformableWorld& world, const btCollisionObject& rigid, double max_gap = 0.0,
    const std::optional<QueryFilter>& filter = std::nullopt);

// The same queries against one body with an explicit contact surface (e.g. the one given to
// SetContactSurface); `object` may be null (then the hits carry none). No filtering.
std::vector<DeformableRayHit> RayTestDeformable(const DeformableBody& body,
                                                const ContactSurface& surface,
                                                const btVector3& from, const btVector3& to,
                                                const btCollisionObject* object = nullptr);
std::vector<DeformableContactHit> ContactTestDeformable(const DeformableBody& body,
                                                        const ContactSurface& surface,
                                                        const btCollisionObject& rigid,
                                                        double max_gap = 0.0,
                                                        const btCollisionObject* object = nullptr);

}  // namespace taut
