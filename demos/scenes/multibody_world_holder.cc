#include "demos/scenes/multibody_world_holder.h"

namespace taut {

void MultiBodyObjects::RemoveFrom(btMultiBodyDynamicsWorld& world) {
  for (auto& constraint : constraints) world.removeMultiBodyConstraint(constraint.get());
  for (auto& collider : colliders) world.removeCollisionObject(collider.get());
  for (auto& body : multibodies) world.removeMultiBody(body.get());
  for (auto& body : rigid_bodies) world.removeRigidBody(body.get());
}

btRigidBody* AddGroundPlane(btMultiBodyDynamicsWorld& world, MultiBodyObjects& objects,
                            double friction) {
  objects.shapes.push_back(std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), 0));
  btRigidBody::btRigidBodyConstructionInfo info(0.0, nullptr, objects.shapes.back().get());
  objects.rigid_bodies.push_back(std::make_unique<btRigidBody>(info));
  btRigidBody* ground = objects.rigid_bodies.back().get();
  ground->setFriction(static_cast<btScalar>(friction));
  world.addRigidBody(ground);
  return ground;
}

void UpdateMultiBodyPose(btMultiBody& body) {
  btAlignedObjectArray<btQuaternion> world_to_local;
  btAlignedObjectArray<btVector3> local_origin;
  body.forwardKinematics(world_to_local, local_origin);
  body.updateCollisionObjectWorldTransforms(world_to_local, local_origin);
}

btMultiBodyLinkCollider* AddLinkCollider(btMultiBodyDynamicsWorld& world, MultiBodyObjects& objects,
                                         btMultiBody* body, int link,
                                         std::unique_ptr<btCollisionShape> shape, double friction) {
  objects.colliders.push_back(std::make_unique<btMultiBodyLinkCollider>(body, link));
  btMultiBodyLinkCollider* collider = objects.colliders.back().get();
  collider->setCollisionShape(shape.get());
  collider->setFriction(static_cast<btScalar>(friction));
  objects.shapes.push_back(std::move(shape));
  if (link < 0) {
    body->setBaseCollider(collider);
  } else {
    body->getLink(link).m_collider = collider;
  }
  world.addCollisionObject(collider, btBroadphaseProxy::DefaultFilter,
                           btBroadphaseProxy::AllFilter);
  UpdateMultiBodyPose(*body);
  return collider;
}

}  // namespace taut
