// Bullet dynamics world that also steps taut deformable bodies (DESIGN.md "One step").
#pragma once

#include <BulletCollision/CollisionDispatch/btEmptyCollisionAlgorithm.h>
#include <BulletDynamics/Dynamics/btDiscreteDynamicsWorld.h>

#include <memory>
#include <vector>

#include "bullet_bridge/deformable_collision_object.h"
#include "constraints/step_stats.h"
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
  // Adds a body built elsewhere (any ElementModel).
  DeformableBody* AddDeformableBody(std::unique_ptr<DeformableBody> body);
  // Removes and destroys the body.
  void RemoveDeformableBody(DeformableBody* body);

  int num_deformable_bodies() const { return static_cast<int>(bodies_.size()); }
  DeformableBody& deformable_body(int i) { return bodies_[i]->body(); }
  const DeformableBody& deformable_body(int i) const { return bodies_[i]->body(); }
  // Statistics of the last substep.
  const StepStats& last_step_stats() const { return stats_; }

 protected:
  // One fixed substep: deformable step (stages 2-7), then Bullet's rigid step.
  void internalSingleStepSimulation(btScalar h) override;

 private:
  // Unconstrained implicit step of every deformable body, then integration.
  void StepDeformableBodies(double h);

  std::vector<std::unique_ptr<DeformableCollisionObject>> bodies_;
  btEmptyAlgorithm::CreateFunc empty_algorithm_;
  StepStats stats_;
};

}  // namespace taut
