#include "bullet_bridge/bullet_world_state.h"

#include <BulletCollision/BroadphaseCollision/btDispatcher.h>
#include <BulletCollision/CollisionShapes/btCollisionShape.h>
#include <BulletCollision/NarrowPhaseCollision/btPersistentManifold.h>
#include <BulletDynamics/ConstraintSolver/btSequentialImpulseConstraintSolver.h>
#include <BulletDynamics/Dynamics/btRigidBody.h>

#include <cstring>
#include <unordered_map>

#include "plugin/common.h"

namespace taut {

namespace {

CollisionObjectState SaveObject(const btCollisionObject& object) {
  CollisionObjectState state;
  state.internal_type = object.getInternalType();
  state.shape_type = object.getCollisionShape()->getShapeType();
  state.shape_name = object.getCollisionShape()->getName();
  state.world_transform = object.getWorldTransform();
  state.interpolation_transform = object.getInterpolationWorldTransform();
  state.interpolation_linear_velocity = object.getInterpolationLinearVelocity();
  state.interpolation_angular_velocity = object.getInterpolationAngularVelocity();
  state.activation_state = object.getActivationState();
  state.deactivation_time = object.getDeactivationTime();
  state.hit_fraction = object.getHitFraction();
  const btRigidBody* rigid = btRigidBody::upcast(&object);
  if (rigid == nullptr) return state;
  state.linear_velocity = rigid->getLinearVelocity();
  state.angular_velocity = rigid->getAngularVelocity();
  state.total_force = rigid->getTotalForce();
  state.total_torque = rigid->getTotalTorque();
  state.has_motion_state = rigid->getMotionState() != nullptr;
  if (state.has_motion_state)
    rigid->getMotionState()->getWorldTransform(state.motion_state_transform);
  return state;
}

ManifoldState SaveManifold(const btPersistentManifold& manifold, int body0, int body1) {
  ManifoldState state;
  state.body0 = body0;
  state.body1 = body1;
  state.breaking_threshold = manifold.getContactBreakingThreshold();
  state.processing_threshold = manifold.getContactProcessingThreshold();
  state.companion_a = manifold.m_companionIdA;
  state.companion_b = manifold.m_companionIdB;
  for (int i = 0; i < manifold.getNumContacts(); ++i)
    state.points.push_back(manifold.getContactPoint(i));
  return state;
}

// True when the two transforms are bitwise equal.
bool SameTransform(const btTransform& a, const btTransform& b) {
  return std::memcmp(&a, &b, sizeof(btTransform)) == 0;
}

// The force f with applyCentralForce(f) = total (Bullet scales by the axis factors); exact for
// factors 0 and 1.
btVector3 UnscaleByFactor(const btVector3& total, const btVector3& factor) {
  btVector3 f = total;
  for (int k = 0; k < 3; ++k) f[k] = factor[k] != 0.0 ? total[k] / factor[k] : 0.0;
  return f;
}

void RestoreRigidBody(const CollisionObjectState& state, btRigidBody& rigid) {
  rigid.updateInertiaTensor();  // I_world^-1 of the restored transform, as after integration
  rigid.setLinearVelocity(state.linear_velocity);
  rigid.setAngularVelocity(state.angular_velocity);
  rigid.clearForces();
  rigid.applyCentralForce(UnscaleByFactor(state.total_force, rigid.getLinearFactor()));
  rigid.applyTorque(UnscaleByFactor(state.total_torque, rigid.getAngularFactor()));
  if (state.has_motion_state && rigid.getMotionState() != nullptr)
    rigid.getMotionState()->setWorldTransform(state.motion_state_transform);
}

void RestoreObject(const CollisionObjectState& state, btCollisionObject& object,
                   btCollisionWorld& world) {
  const bool moved = !SameTransform(object.getWorldTransform(), state.world_transform);
  object.setWorldTransform(state.world_transform);
  object.setInterpolationWorldTransform(state.interpolation_transform);
  object.setInterpolationLinearVelocity(state.interpolation_linear_velocity);
  object.setInterpolationAngularVelocity(state.interpolation_angular_velocity);
  object.forceActivationState(state.activation_state);
  object.setDeactivationTime(state.deactivation_time);
  object.setHitFraction(state.hit_fraction);
  if (btRigidBody* rigid = btRigidBody::upcast(&object)) RestoreRigidBody(state, *rigid);
  // The next step refreshes the bounds of active objects only (unless forced for all).
  if (moved && !object.isActive() && object.getBroadphaseHandle() != nullptr)
    world.updateSingleAabb(&object);
}

// For each saved manifold, the index of the world's manifold between the same objects (in the
// same order; the k-th saved one of a pair takes the k-th current one), or -1.
std::vector<int> MatchManifolds(const std::vector<ManifoldState>& saved, btDispatcher& dispatcher,
                                const btCollisionObjectArray& objects) {
  std::vector<int> match(saved.size(), -1);
  std::vector<char> taken(dispatcher.getNumManifolds(), 0);
  for (size_t s = 0; s < saved.size(); ++s) {
    for (int m = 0; m < dispatcher.getNumManifolds(); ++m) {
      const btPersistentManifold* manifold = dispatcher.getManifoldByIndexInternal(m);
      if (taken[m] || manifold->getBody0() != objects[saved[s].body0] ||
          manifold->getBody1() != objects[saved[s].body1])
        continue;
      match[s] = m;
      taken[m] = 1;
      break;
    }
  }
  return match;
}

// True when a saved manifold with contact points has no counterpart in the world.
bool MissesContacts(const std::vector<ManifoldState>& saved, const std::vector<int>& match) {
  for (size_t s = 0; s < saved.size(); ++s)
    if (match[s] < 0 && !saved[s].points.empty()) return true;
  return false;
}

void WriteManifold(const ManifoldState& state, btPersistentManifold& manifold) {
  manifold.clearManifold();  // user caches of the points it held
  manifold.setContactBreakingThreshold(state.breaking_threshold);
  manifold.setContactProcessingThreshold(state.processing_threshold);
  manifold.m_companionIdA = state.companion_a;
  manifold.m_companionIdB = state.companion_b;
  manifold.setNumContacts(static_cast<int>(state.points.size()));
  for (size_t i = 0; i < state.points.size(); ++i) {
    btManifoldPoint& point = manifold.getContactPoint(static_cast<int>(i));
    point = state.points[i];
    point.m_userPersistentData = nullptr;  // the saved world's user cache is not ours
  }
}

// The dispatcher's manifolds in the order `order` (indices into the current array), with the
// index each keeps of its slot (btCollisionDispatcher::releaseManifold swaps by it).
void ReorderManifolds(const std::vector<int>& order, btDispatcher& dispatcher) {
  std::vector<btPersistentManifold*> manifolds;
  for (int m : order) manifolds.push_back(dispatcher.getManifoldByIndexInternal(m));
  btPersistentManifold** slots = dispatcher.getInternalManifoldPointer();
  for (size_t i = 0; i < manifolds.size(); ++i) {
    slots[i] = manifolds[i];
    manifolds[i]->m_index1a = static_cast<int>(i);
  }
}

void RestoreManifolds(const std::vector<ManifoldState>& saved, btDiscreteDynamicsWorld& world) {
  btDispatcher& dispatcher = *world.getDispatcher();
  const btCollisionObjectArray& objects = world.getCollisionObjectArray();
  std::vector<int> match = MatchManifolds(saved, dispatcher, objects);
  if (MissesContacts(saved, match)) {
    // Bullet makes the pairs and manifolds of the restored poses; their points are replaced.
    world.performDiscreteCollisionDetection();
    match = MatchManifolds(saved, dispatcher, objects);
  }
  std::vector<int> order;
  std::vector<char> matched(dispatcher.getNumManifolds(), 0);
  for (size_t s = 0; s < saved.size(); ++s) {
    if (match[s] < 0) continue;
    WriteManifold(saved[s], *dispatcher.getManifoldByIndexInternal(match[s]));
    order.push_back(match[s]);
    matched[match[s]] = 1;
  }
  for (int m = 0; m < dispatcher.getNumManifolds(); ++m) {
    if (matched[m]) continue;
    dispatcher.getManifoldByIndexInternal(m)->clearManifold();
    order.push_back(m);
  }
  ReorderManifolds(order, dispatcher);
}

}  // namespace

BulletWorldState SaveBulletWorldState(const btDiscreteDynamicsWorld& world) {
  BulletWorldState state;
  const btCollisionObjectArray& objects = world.getCollisionObjectArray();
  std::unordered_map<const btCollisionObject*, int> index_of;
  for (int i = 0; i < objects.size(); ++i) {
    state.objects.push_back(SaveObject(*objects[i]));
    index_of[objects[i]] = i;
  }
  for (int j = 0; j < world.getNumConstraints(); ++j) {
    const btTypedConstraint& joint = *world.getConstraint(j);
    state.joints.push_back(
        {joint.getConstraintType(), joint.isEnabled(), joint.getAppliedImpulse()});
  }
  // Read only: Bullet's dispatcher and solver have no const accessors for these.
  auto& dispatcher = const_cast<btDispatcher&>(*world.getDispatcher());
  for (int m = 0; m < dispatcher.getNumManifolds(); ++m) {
    const btPersistentManifold& manifold = *dispatcher.getManifoldByIndexInternal(m);
    const auto body0 = index_of.find(manifold.getBody0());
    const auto body1 = index_of.find(manifold.getBody1());
    if (body0 == index_of.end() || body1 == index_of.end()) continue;  // not between world objects
    state.manifolds.push_back(SaveManifold(manifold, body0->second, body1->second));
  }
  auto* solver = const_cast<btDiscreteDynamicsWorld&>(world).getConstraintSolver();
  state.has_solver_seed = solver->getSolverType() == BT_SEQUENTIAL_IMPULSE_SOLVER;
  if (state.has_solver_seed)
    state.solver_seed = static_cast<btSequentialImpulseConstraintSolver*>(solver)->getRandSeed();
  return state;
}

void CheckBulletWorldState(const BulletWorldState& state, const btDiscreteDynamicsWorld& world) {
  const btCollisionObjectArray& objects = world.getCollisionObjectArray();
  TAUT_DEMAND(static_cast<int>(state.objects.size()) == objects.size(),
              "RestoreSnapshot: the world has ", objects.size(),
              " collision objects, the snapshot ", state.objects.size());
  for (int i = 0; i < objects.size(); ++i) {
    const CollisionObjectState& saved = state.objects[i];
    const btCollisionObject& object = *objects[i];
    TAUT_DEMAND(
        saved.internal_type == object.getInternalType() &&
            saved.shape_type == object.getCollisionShape()->getShapeType(),
        "RestoreSnapshot: collision object ", i, " is a ",
        object.getInternalType() == btCollisionObject::CO_RIGID_BODY ? "rigid body"
                                                                     : "collision object",
        " of shape ", object.getCollisionShape()->getName(), " (type ",
        object.getCollisionShape()->getShapeType(), "), in the snapshot a ",
        saved.internal_type == btCollisionObject::CO_RIGID_BODY ? "rigid body" : "collision object",
        " of shape ", saved.shape_name, " (type ", saved.shape_type, ")");
  }
  TAUT_DEMAND(static_cast<int>(state.joints.size()) == world.getNumConstraints(),
              "RestoreSnapshot: the world has ", world.getNumConstraints(),
              " joints, the snapshot ", state.joints.size());
  for (int j = 0; j < world.getNumConstraints(); ++j)
    TAUT_DEMAND(state.joints[j].type == world.getConstraint(j)->getConstraintType(),
                "RestoreSnapshot: joint ", j, " is of type ",
                world.getConstraint(j)->getConstraintType(), ", in the snapshot of type ",
                state.joints[j].type);
}

void RestoreBulletWorldState(const BulletWorldState& state, btDiscreteDynamicsWorld& world) {
  btCollisionObjectArray& objects = world.getCollisionObjectArray();
  for (int i = 0; i < objects.size(); ++i) RestoreObject(state.objects[i], *objects[i], world);
  for (int j = 0; j < world.getNumConstraints(); ++j) {
    btTypedConstraint& joint = *world.getConstraint(j);
    joint.setEnabled(state.joints[j].enabled);
    joint.internalSetAppliedImpulse(state.joints[j].applied_impulse);
  }
  RestoreManifolds(state.manifolds, world);
  if (state.has_solver_seed &&
      world.getConstraintSolver()->getSolverType() == BT_SEQUENTIAL_IMPULSE_SOLVER)
    static_cast<btSequentialImpulseConstraintSolver*>(world.getConstraintSolver())
        ->setRandSeed(state.solver_seed);
}

}  // namespace taut
