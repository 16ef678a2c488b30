#include "demos/scenes/bullet_world_holder.h"

namespace taut {

BulletWorldHolder::BulletWorldHolder() { world.setGravity(btVector3(0, 0, -9.81)); }

btRigidBody* BulletWorldHolder::AddStaticGround(double friction) {
  shapes.push_back(std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), 0));
  btRigidBody::btRigidBodyConstructionInfo info(0.0, nullptr, shapes.back().get());
  rigid_bodies.push_back(std::make_unique<btRigidBody>(info));
  rigid_bodies.back()->setFriction(friction);
  world.addRigidBody(rigid_bodies.back().get());
  return rigid_bodies.back().get();
}

btRigidBody* BulletWorldHolder::AddRigidBody(std::unique_ptr<btCollisionShape> shape, double mass,
                                             const btVector3& position, double friction,
                                             double restitution) {
  btVector3 inertia(0, 0, 0);
  if (mass > 0.0) shape->calculateLocalInertia(mass, inertia);
  btTransform start;
  start.setIdentity();
  start.setOrigin(position);
  motion_states.push_back(std::make_unique<btDefaultMotionState>(start));
  btRigidBody::btRigidBodyConstructionInfo info(mass, motion_states.back().get(), shape.get(),
                                                inertia);
  info.m_friction = friction;
  info.m_restitution = restitution;
  shapes.push_back(std::move(shape));
  rigid_bodies.push_back(std::make_unique<btRigidBody>(info));
  world.addRigidBody(rigid_bodies.back().get());
  return rigid_bodies.back().get();
}

BulletWorldHolder::~BulletWorldHolder() {
  for (auto& body : rigid_bodies) world.removeRigidBody(body.get());
}

}  // namespace taut
