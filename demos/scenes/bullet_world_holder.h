// The Bullet objects every scene needs, owned together, with a taut DeformableWorld on top.
#pragma once

#include <btBulletDynamicsCommon.h>

#include <memory>

#include "bullet_bridge/deformable_world.h"

namespace taut {

// Collision configuration, dispatcher, broadphase, rigid solver and the world, in build order.
struct BulletWorldHolder {
  BulletWorldHolder();
  ~BulletWorldHolder();
  // Adds a static ground plane z = 0 with the given Coulomb friction; the holder owns it.
  btRigidBody* AddStaticGround(double friction = 1.0);
  // Adds a rigid body of `shape` (the holder owns it) with its centre of mass at `position`:
  // dynamic when mass > 0 (inertia from the shape), static when mass = 0.
  btRigidBody* AddRigidBody(std::unique_ptr<btCollisionShape> shape, double mass,
                            const btVector3& position, double friction = 0.5,
                            double restitution = 0.0);
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher{&configuration};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  DeformableWorld world{&dispatcher, &broadphase, &solver, &configuration};
  // Rigid bodies and shapes added by the scene, deleted with the holder.
  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  std::vector<std::unique_ptr<btRigidBody>> rigid_bodies;
  std::vector<std::unique_ptr<btDefaultMotionState>> motion_states;
};

}  // namespace taut
