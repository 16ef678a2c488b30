// Bullet dynamics world that also steps taut deformable bodies (DESIGN.md "One step").
#pragma once

#include <BulletCollision/CollisionDispatch/btEmptyCollisionAlgorithm.h>
#include <BulletDynamics/Dynamics/btDiscreteDynamicsWorld.h>

#include <memory>
#include <vector>

#include "bullet_bridge/deformable_collision_object.h"
#include "bullet_bridge/rigid_contact_source.h"
#include "constraints/energy_limit_constraint.h"
#include "constraints/sqp_solver.h"
#include "constraints/step_stats.h"
#include "constraints/strain_limit_constraint.h"
#include "plugin/hex_element_model.h"
#include "plugin/tet_mesh.h"

namespace taut {

// Drop-in replacement for btDiscreteDynamicsWorld. Deformable bodies live in Bullet's broadphase
// as btCollisionObjects (AABBs refreshed every substep) and are stepped inside stepSimulation's
// fixed substeps together with the rigid bodies. Without deformable bodies every substep is
// exactly btDiscreteDynamicsWorld's.
class DeformableWorld : public btDiscreteDynamicsWorld {
 public:
  DeformableWorld(btDispatcher* dispatcher, btBroadphaseInterface* broadphase,
                  btConstraintSolver* solver, btCollisionConfiguration* configuration);
  ~DeformableWorld() override;

  // Makes a co-rotational tet body from a mesh (validated; throws InputError) and adds it.
  // The world owns the body; the pointer stays valid until RemoveDeformableBody.
  DeformableBody* AddTetBody(const TetMesh& mesh, const DeformableBodySettings& settings);
  DeformableBody* AddTetBody(std::shared_ptr<const TetMesh> mesh,
                             const DeformableBodySettings& settings);
  // Makes a co-rotational hex body from a lattice (validated; throws InputError) and adds it;
  // `method` picks the element rotation (MATH.md §4). Ownership as for AddTetBody.
  DeformableBody* AddHexBody(const HexLattice& lattice, const DeformableBodySettings& settings,
                             HexRotationMethod method = HexRotationMethod::kCenterPolar);
  DeformableBody* AddHexBody(std::shared_ptr<const HexLattice> lattice,
                             const DeformableBodySettings& settings,
                             HexRotationMethod method = HexRotationMethod::kCenterPolar);
  // Adds a body built elsewhere (any ElementModel).
  DeformableBody* AddDeformableBody(std::unique_ptr<DeformableBody> body);
  // Removes and destroys the body.
  void RemoveDeformableBody(DeformableBody* body);

  // Limits the principal stretches of every tet of `body` (paper A). Replaces earlier strain
  // limits of that body. Throws InputError for invalid settings or a body that is not a tet body.
  StrainLimitConstraint* SetStrainLimits(DeformableBody* body, const StrainLimitSettings& limits);
  // Limits the elastic energy of every element (tet or hex) of `body` to U_max (paper B:
  // C = 1 - U_e/U_max).
  // Replaces earlier energy limits of the body; throws InputError for invalid settings.
  EnergyLimitConstraint* SetEnergyLimits(DeformableBody* body, const EnergyLimitSettings& limits);
  // Pins `nodes` of `body` to `rigid` (a bone driving soft flesh): every substep the nodes are
  // driven kinematically to their rest offsets in the rigid body's current frame. One-way: the
  // rigid body feels no reaction (use kinematic or static bodies). Throws InputError for a node
  // out of range.
  void AttachNodesToRigidBody(DeformableBody* body, const std::vector<int>& nodes,
                              const btRigidBody* rigid);
  // Removes every constraint source (limits) of the body.
  void ClearLimits(DeformableBody* body);
  // Solver settings used by every constrained body.
  SqpSettings& mutable_solver_settings() { return solver_settings_; }
  const SqpSettings& solver_settings() const { return solver_settings_; }

  int num_deformable_bodies() const { return static_cast<int>(bodies_.size()); }
  DeformableBody& deformable_body(int i) { return bodies_[i]->body(); }
  const DeformableBody& deformable_body(int i) const { return bodies_[i]->body(); }
  // Statistics of the last substep.
  const StepStats& last_step_stats() const { return stats_; }

 protected:
  // One fixed substep: deformable step (stages 2-7), then Bullet's rigid step.
  void internalSingleStepSimulation(btScalar h) override;

 private:
  // Unconstrained implicit step of every deformable body, limits and contacts, integration.
  void StepDeformableBodies(double h);
  // Static and kinematic rigid objects (contact partners of deformables), into objects.
  void CollectStaticObjects(std::vector<const btCollisionObject*>& objects) const;

  // A body with its Bullet proxy, its constraint sources and its solver (warm starts).
  struct Entry {
    std::unique_ptr<DeformableCollisionObject> object;
    std::vector<std::unique_ptr<ConstraintSource>> sources;
    std::unique_ptr<RigidContactSource> contacts;  // made when the world has static objects
    // Nodes pinned to rigid bodies, with their offsets in the rigid body's frame.
    struct Attachment {
      const btRigidBody* rigid;
      std::vector<int> nodes;
      std::vector<Vec3> local;
    };
    std::vector<Attachment> attachments;
    SqpSolver solver;
    DeformableBody& body() { return object->body(); }
    btCollisionObject& collision_object() { return object->collision_object(); }
  };
  // The entry of a body; throws InputError when the body is not in this world.
  Entry& FindEntry(const DeformableBody* body);
  // Installs `source` on the body's entry, replacing any earlier source of the same type T.
  template <typename T>
  T* ReplaceSource(DeformableBody* body, std::unique_ptr<T> source);

  std::vector<std::unique_ptr<Entry>> bodies_;
  SqpSettings solver_settings_;
  int next_source_id_ = 0;
  btEmptyAlgorithm::CreateFunc empty_algorithm_;
  StepStats stats_;
};

}  // namespace taut
