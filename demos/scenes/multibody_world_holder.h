// The Bullet objects of a multibody scene, owned together, with a Bullet multibody world on top
// (taut's DeformableMultiBodyWorld, or stock btMultiBodyDynamicsWorld for comparisons).
#pragma once

#include <BulletDynamics/Featherstone/btMultiBody.h>
#include <BulletDynamics/Featherstone/btMultiBodyConstraint.h>
#include <BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h>
#include <BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h>
#include <BulletDynamics/Featherstone/btMultiBodyLinkCollider.h>
#include <btBulletDynamicsCommon.h>

#include <memory>
#include <vector>

#include "bullet_bridge/deformable_world.h"

namespace taut {

// Shapes, rigid bodies, multibodies, link colliders and multibody constraints a scene made.
struct MultiBodyObjects {
  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  std::vector<std::unique_ptr<btRigidBody>> rigid_bodies;
  std::vector<std::unique_ptr<btMultiBody>> multibodies;
  std::vector<std::unique_ptr<btMultiBodyLinkCollider>> colliders;
  std::vector<std::unique_ptr<btMultiBodyConstraint>> constraints;
  // Takes every object out of `world` (before either is destroyed).
  void RemoveFrom(btMultiBodyDynamicsWorld& world);
};

// Collision configuration, dispatcher, broadphase, multibody solver and the world, in build
// order; gravity -9.81 m/s^2 along z.
template <class World>
struct MultiBodyWorldHolderOf {
  MultiBodyWorldHolderOf() { world.setGravity(btVector3(0, 0, -9.81)); }
  ~MultiBodyWorldHolderOf() { objects.RemoveFrom(world); }
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher{&configuration};
  btDbvtBroadphase broadphase;
  btMultiBodyConstraintSolver solver;
  World world{&dispatcher, &broadphase, &solver, &configuration};
  MultiBodyObjects objects;
};

// Adds a static ground plane z = 0 with Coulomb friction `friction`.
btRigidBody* AddGroundPlane(btMultiBodyDynamicsWorld& world, MultiBodyObjects& objects,
                            double friction);
// Gives link `link` (-1: the base) of `body` a collider of `shape` (owned by `objects`) with
// friction `friction`, placed at the link's current pose, and adds it to the world.
btMultiBodyLinkCollider* AddLinkCollider(btMultiBodyDynamicsWorld& world, MultiBodyObjects& objects,
                                         btMultiBody* body, int link,
                                         std::unique_ptr<btCollisionShape> shape, double friction);
// Updates the cached link frames and collider transforms of `body` from its joint positions.
void UpdateMultiBodyPose(btMultiBody& body);

}  // namespace taut
