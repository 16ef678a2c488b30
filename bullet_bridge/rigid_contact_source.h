// Contacts of a deformable body's boundary nodes with Bullet's static and kinematic rigid
// objects, as SQP rows: normal C = gap >= 0 and two Coulomb friction rows (MATH.md §5).
#pragma once

#include <BulletCollision/CollisionDispatch/btCollisionObject.h>

#include <vector>

#include "constraints/constraint_row.h"

namespace taut {

// Rigid objects are treated as immovable during the step (static, or kinematic with the motion
// Bullet gave them). Two-way coupling with dynamic rigid bodies is not part of this source.
class RigidContactSource final : public BodyConstraintSource {
 public:
  // `friction` is the body's Coulomb coefficient, combined with each object's by the product
  // (Bullet's default combiner); `margin` [m] is how close a node must be to get rows.
  RigidContactSource(const DeformableBody& body, int source_id, double friction, double margin);

  // The rigid objects to test this step (static and kinematic objects of the world).
  void set_objects(const std::vector<const btCollisionObject*>& objects) { objects_ = objects; }

  const DeformableBody& body() const override { return body_; }
  int AppendRows(const VecX& x, int body_index, std::vector<ConstraintRow>& rows) override;
  double CalcMaxViolation(const VecX& x) const override;
  double CalcViolationSum(const VecX& x) const override;
  // Largest penetration max(0, -gap) at x [m].
  double CalcMaxPenetration(const VecX& x) const { return CalcMaxViolation(x); }

 private:
  // Smallest gap of node i over the objects (+inf when none is within the margin).
  double CalcNodeGap(const VecX& x, int node) const;

  const DeformableBody& body_;
  std::uint64_t key_prefix_;
  double friction_;
  double margin_;
  std::vector<int> surface_nodes_;  // free boundary nodes
  std::vector<const btCollisionObject*> objects_;
};

}  // namespace taut
