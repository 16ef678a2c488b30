// Bullet's collision groups and masks (and ignore lists) between a deformable and another
// collision object, and for queries (rays, contact tests) with a group and mask of their own.
#pragma once

#include <BulletCollision/BroadphaseCollision/btBroadphaseProxy.h>
#include <BulletCollision/CollisionDispatch/btCollisionObject.h>

namespace taut {

// A query's own group and mask, as in btCollisionWorld::RayResultCallback (defaults: Bullet's
// DefaultFilter group, every mask bit).
struct QueryFilter {
  int group = btBroadphaseProxy::DefaultFilter;
  int mask = btBroadphaseProxy::AllFilter;
};

// True when `deformable` and `other` may touch, by the rules of Bullet's default pair filter
// (btHashedOverlappingPairCache::needsBroadphaseCollision) and btCollisionDispatcher::
// needsCollision: (group_a & mask_b) != 0 and (group_b & mask_a) != 0 on their broadphase
// proxies, and neither lists the other with setIgnoreCollisionCheck. False when either object is
// not in a world (no broadphase proxy). A user overlap-filter callback is not consulted.
bool ShouldCollide(const btCollisionObject& deformable, const btCollisionObject& other);

// True when a query with `filter` sees `object`, as btCollisionWorld's RayResultCallback::
// needsCollision and ContactResultCallback::needsCollision decide it: (proxy group & query mask)
// != 0 and (query group & proxy mask) != 0. False for an object without a broadphase proxy.
bool PassesQueryFilter(const btCollisionObject& object, const QueryFilter& filter);

}  // namespace taut
