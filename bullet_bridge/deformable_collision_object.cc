#include "bullet_bridge/deformable_collision_object.h"

#include "bullet_bridge/eigen_bullet.h"

namespace taut {

DeformableBodyShape::DeformableBodyShape(const DeformableBody* body) : body_(body) {
  m_shapeType = kDeformableShapeType;
}

void DeformableBodyShape::getAabb(const btTransform&, btVector3& aabb_min,
                                  btVector3& aabb_max) const {
  Vec3 lo, hi;
  body_->CalcBounds(lo, hi);
  const btVector3 margin(margin_, margin_, margin_);
  aabb_min = ToBullet(lo) - margin;
  aabb_max = ToBullet(hi) + margin;
}

void DeformableBodyShape::calculateLocalInertia(btScalar, btVector3& inertia) const {
  inertia.setZero();  // never used: the body is not a btRigidBody
}

DeformableCollisionObject::DeformableCollisionObject(std::unique_ptr<DeformableBody> body)
    : body_(std::move(body)), shape_(body_.get()) {
  object_.setCollisionShape(&shape_);
  object_.setWorldTransform(btTransform::getIdentity());
  object_.setCollisionFlags(0);  // not static: pairs with static ground are kept for contact
  object_.setActivationState(DISABLE_DEACTIVATION);
  object_.setUserPointer(body_.get());
}

}  // namespace taut
