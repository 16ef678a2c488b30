#include "bullet_bridge/deformable_queries.h"

#include <algorithm>

#include "bullet_bridge/eigen_bullet.h"
#include "bullet_bridge/point_shape_distance.h"
#include "plugin/surface_hit_element.h"
#include "plugin/surface_ray_cast.h"

namespace taut {
namespace {

// A deformable of the world with its collision object.
struct DeformableObject {
  const DeformableBody* body;
  btCollisionObject* object;
};

// The world's deformables, each with the collision object whose user pointer is its body
// (DeformableCollisionObject), in the world's body order.
std::vector<DeformableObject> ListDeformableObjects(const DeformableWorld& world) {
  std::vector<DeformableObject> list;
  const btCollisionObjectArray& objects = world.getCollisionObjectArray();
  for (int i = 0; i < world.num_deformable_bodies(); ++i) {
    const DeformableBody* body = &world.deformable_body(i);
    for (int k = 0; k < objects.size(); ++k) {
      if (objects[k]->getCollisionShape()->getShapeType() == kDeformableShapeType &&
          objects[k]->getUserPointer() == body) {
        list.push_back({body, objects[k]});
        break;
      }
    }
  }
  return list;
}

// Stage 1 of a query: the contact surface of a world body (see the header: its model's boundary).
ContactSurface QuerySurface(const DeformableBody& body) {
  return MakeBodyContactSurface(body.model());
}

// Throws InputError for a segment with a non-finite end (whether or not a body is seen).
void CheckSegment(const btVector3& from, const btVector3& to) {
  TAUT_DEMAND(ToEigen(from).allFinite() && ToEigen(to).allFinite(), "ray query: the segment (",
              ToEigen(from).transpose(), ") -> (", ToEigen(to).transpose(), ") is not finite");
}

// Throws InputError for a negative contact-test gap.
void CheckMaxGap(double max_gap) {
  TAUT_DEMAND(max_gap >= 0.0, "contact test: max_gap must be >= 0 m, got ", max_gap);
}

// Stage 2 of a ray query: the ray's crossings of every body `sees` lets through, by fraction.
template <typename Sees>
std::vector<DeformableRayHit> CastOnWorld(const DeformableWorld& world, const btVector3& from,
                                          const btVector3& to, const Sees& sees) {
  CheckSegment(from, to);
  std::vector<DeformableRayHit> hits;
  for (const DeformableObject& d : ListDeformableObjects(world)) {
    if (!sees(*d.object)) continue;
    std::vector<DeformableRayHit> body_hits =
        RayTestDeformable(*d.body, QuerySurface(*d.body), from, to, d.object);
    hits.insert(hits.end(), body_hits.begin(), body_hits.end());
  }
  std::stable_sort(
      hits.begin(), hits.end(),
      [](const DeformableRayHit& a, const DeformableRayHit& b) { return a.fraction < b.fraction; });
  return hits;
}

// The query filter's test, as a predicate on collision objects.
auto SeenBy(const QueryFilter& filter) {
  return [filter](const btCollisionObject& object) { return PassesQueryFilter(object, filter); };
}

}  // namespace

std::vector<DeformableRayHit> RayTestDeformable(const DeformableBody& body,
                                                const ContactSurface& surface,
                                                const btVector3& from, const btVector3& to,
                                                const btCollisionObject* object) {
  const std::vector<Vec3> points = CalcContactPointPositions(surface, body.x());
  std::vector<DeformableRayHit> hits;
  for (const SurfaceRayHit& s : CastSegmentOnSurface(surface, points, ToEigen(from), ToEigen(to))) {
    DeformableRayHit hit;
    hit.body = &body;
    hit.object = object;
    hit.fraction = s.fraction;
    hit.point = s.point;
    hit.normal = s.normal;
    hit.triangle = s.triangle;
    hit.element = FindHitElement(body.model(), body.x(), surface, s.triangle, s.point);
    hits.push_back(hit);
  }
  return hits;
}

std::optional<DeformableRayHit> RayTestDeformables(const DeformableWorld& world,
                                                   const btVector3& from, const btVector3& to,
                                                   const QueryFilter& filter) {
  std::vector<DeformableRayHit> hits = CastOnWorld(world, from, to, SeenBy(filter));
  if (hits.empty()) return std::nullopt;
  return hits.front();
}

std::vector<DeformableRayHit> RayTestAllDeformables(const DeformableWorld& world,
                                                    const btVector3& from, const btVector3& to,
                                                    const QueryFilter& filter) {
  return CastOnWorld(world, from, to, SeenBy(filter));
}

void RayTestDeformables(const DeformableWorld& world, const btVector3& from, const btVector3& to,
                        btCollisionWorld::RayResultCallback& callback) {
  const auto sees = [&callback](btCollisionObject& object) {
    return object.getBroadphaseHandle() != nullptr &&
           callback.needsCollision(object.getBroadphaseHandle());
  };
  for (const DeformableRayHit& hit : CastOnWorld(world, from, to, sees)) {
    if (hit.fraction > callback.m_closestHitFraction) break;  // sorted: the rest are farther
    btCollisionWorld::LocalShapeInfo shape_info;
    shape_info.m_shapePart = 0;
    shape_info.m_triangleIndex = hit.triangle;
    btCollisionWorld::LocalRayResult result(hit.object, &shape_info, ToBullet(hit.normal),
                                            btScalar(hit.fraction));
    callback.addSingleResult(result, true);
  }
}

std::vector<DeformableContactHit> ContactTestDeformable(const DeformableBody& body,
                                                        const ContactSurface& surface,
                                                        const btCollisionObject& rigid,
                                                        double max_gap,
                                                        const btCollisionObject* object) {
  CheckMaxGap(max_gap);
  const btCollisionShape& shape = *rigid.getCollisionShape();
  TAUT_DEMAND(shape.getShapeType() != kDeformableShapeType,
              "contact test: the object tested against is itself a deformable body");
  const std::vector<Vec3> points = CalcContactPointPositions(surface, body.x());
  std::vector<DeformableContactHit> hits;
  for (std::size_t p = 0; p < points.size(); ++p) {
    // gap = signed distance to the shape (point_shape_distance.h), kept when gap <= max_gap.
    const PointContact c =
        CalcPointShapeDistance(points[p], shape, rigid.getWorldTransform(), max_gap);
    if (!c.valid || c.gap > max_gap) continue;
    const ContactPoint& cp = surface.points[p];
    DeformableContactHit hit;
    hit.body = &body;
    hit.object = object;
    hit.point = static_cast<int>(p);
    hit.node = cp.num_nodes == 1 ? cp.nodes[0] : -1;
    hit.position = points[p];
    hit.normal = c.normal;
    hit.point_on_shape = c.point_on_shape;
    hit.depth = -c.gap;
    hits.push_back(hit);
  }
  return hits;
}

std::vector<DeformableContactHit> ContactTestDeformables(const DeformableWorld& world,
                                                         const btCollisionObject& rigid,
                                                         double max_gap,
                                                         const std::optional<QueryFilter>& filter) {
  CheckMaxGap(max_gap);
  std::vector<DeformableContactHit> hits;
  for (const DeformableObject& d : ListDeformableObjects(world)) {
    // Groups and masks: the query's own, else the rigid object's as a contact pair would use.
    const bool seen = filter ? PassesQueryFilter(*d.object, *filter)
                      : rigid.getBroadphaseHandle() != nullptr ? ShouldCollide(*d.object, rigid)
                                                               : true;
    if (!seen) continue;
    std::vector<DeformableContactHit> body_hits =
        ContactTestDeformable(*d.body, QuerySurface(*d.body), rigid, max_gap, d.object);
    hits.insert(hits.end(), body_hits.begin(), body_hits.end());
  }
  return hits;
}

}  // namespace taut
