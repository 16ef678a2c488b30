// The Bullet part of a world snapshot (bullet_bridge/world_snapshot.h): what the next substep of a
// btDiscreteDynamicsWorld depends on besides its configuration. Rigid bodies (transforms,
// velocities, Bullet's interpolation state, sleeping), joints (enabled, last impulse), the contact
// manifolds with their points (the warm starts of Bullet's solver and of taut's rigid-contact
// rows, in dispatcher order) and the solver's random seed.
#pragma once

#include <BulletCollision/NarrowPhaseCollision/btManifoldPoint.h>
#include <BulletDynamics/Dynamics/btDiscreteDynamicsWorld.h>

#include <string>
#include <vector>

namespace taut {

// One collision object of the world array (rigid bodies, static objects, deformable proxies).
struct CollisionObjectState {
  int internal_type = 0;        // btCollisionObject::CO_RIGID_BODY, ... (checked on restore)
  int shape_type = 0;           // BroadphaseNativeTypes (checked on restore)
  std::string shape_name;       // for messages
  btTransform world_transform;  // centre-of-mass frame [m]
  btTransform interpolation_transform;       // Bullet's predicted / interpolated transform [m]
  btVector3 interpolation_linear_velocity;   // [m/s]
  btVector3 interpolation_angular_velocity;  // [rad/s]
  int activation_state = 0;                  // ACTIVE_TAG, ISLAND_SLEEPING, ...
  btScalar deactivation_time = 0.0;          // time below the sleeping thresholds [s]
  btScalar hit_fraction = 1.0;               // continuous collision detection's time of impact [-]
  // Rigid bodies only.
  btVector3 linear_velocity;   // [m/s]
  btVector3 angular_velocity;  // [rad/s]
  btVector3 total_force;       // queued by applyForce for the next stepSimulation [N]
  btVector3 total_torque;      // [N m]
  bool has_motion_state = false;
  btTransform motion_state_transform;  // what the motion state reports (kinematic bodies' input)
};

// One joint of the world's constraint array.
struct JointState {
  int type = 0;  // btTypedConstraintType (checked on restore)
  bool enabled = true;
  btScalar applied_impulse = 0.0;  // of the last step [N s] (breaking, feedback)
};

// One persistent contact manifold of the dispatcher.
struct ManifoldState {
  int body0 = -1, body1 = -1;           // collision object indices
  btScalar breaking_threshold = 0.0;    // [m]
  btScalar processing_threshold = 0.0;  // [m]
  int companion_a = 0, companion_b = 0;
  std::vector<btManifoldPoint> points;  // with their applied impulses (warm starts) and lifetimes
};

struct BulletWorldState {
  std::vector<CollisionObjectState> objects;  // world array order
  std::vector<JointState> joints;             // world constraint order
  std::vector<ManifoldState> manifolds;       // dispatcher order
  bool has_solver_seed = false;               // the solver is a btSequentialImpulseConstraintSolver
  unsigned long solver_seed = 0;
};

// The state of `world` (read only; Bullet's dispatcher and solver lack const accessors).
BulletWorldState SaveBulletWorldState(const btDiscreteDynamicsWorld& world);
// Throws InputError saying what differs when `state` is not of a world with the same collision
// objects (count, kind, shape type) and joints (count, type) as `world`.
void CheckBulletWorldState(const BulletWorldState& state, const btDiscreteDynamicsWorld& world);
// Puts `state` (checked) back into `world`. Manifolds are matched to the world's current ones by
// their pair of objects; a saved manifold the world no longer has is made by running Bullet's
// collision detection at the restored poses first. Matched manifolds get the saved points and
// the saved order in the dispatcher; the others are emptied and follow.
void RestoreBulletWorldState(const BulletWorldState& state, btDiscreteDynamicsWorld& world);

}  // namespace taut
