// A taut deformable body seen by Bullet's broadphase: a btCollisionObject whose shape reports the
// body's current bounding box.
#pragma once

#include <BulletCollision/CollisionDispatch/btCollisionObject.h>
#include <BulletCollision/CollisionShapes/btCollisionShape.h>

#include "plugin/deformable_body.h"

namespace taut {

// Shape type Bullet's dispatcher sees for deformables. The world registers an empty collision
// algorithm for it so Bullet never builds manifolds for deformables; taut detects those contacts.
constexpr int kDeformableShapeType = HFFLUID_SHAPE_PROXYTYPE;

// Collision shape whose AABB is the body's current bounds (world coordinates, identity transform)
// grown by the margin. It has no Bullet-side contact geometry.
class DeformableBodyShape : public btCollisionShape {
 public:
  explicit DeformableBodyShape(const DeformableBody* body);
  void getAabb(const btTransform& t, btVector3& aabb_min, btVector3& aabb_max) const override;
  void setLocalScaling(const btVector3& scaling) override { scaling_ = scaling; }
  const btVector3& getLocalScaling() const override { return scaling_; }
  void calculateLocalInertia(btScalar mass, btVector3& inertia) const override;
  const char* getName() const override { return "tautDeformableBody"; }
  void setMargin(btScalar margin) override { margin_ = margin; }
  btScalar getMargin() const override { return margin_; }

 private:
  const DeformableBody* body_;
  btVector3 scaling_{1, 1, 1};
  btScalar margin_ = btScalar(0.01);
};

// Owns the body, its shape and the collision object registered with the world.
class DeformableCollisionObject {
 public:
  explicit DeformableCollisionObject(std::unique_ptr<DeformableBody> body);
  DeformableBody& body() { return *body_; }
  const DeformableBody& body() const { return *body_; }
  btCollisionObject& collision_object() { return object_; }

 private:
  std::unique_ptr<DeformableBody> body_;
  DeformableBodyShape shape_;
  btCollisionObject object_;
};

}  // namespace taut
