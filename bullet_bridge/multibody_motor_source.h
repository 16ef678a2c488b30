// The joint motors (btMultiBodyJointMotor) of the multibodies in a deformable island as island
// rows, so a gripper's motor force and its fingers' contact forces are solved together.
#pragma once

#include <BulletDynamics/Featherstone/btMultiBodyJointMotor.h>

#include <vector>

#include "bullet_bridge/multibody_island_body.h"
#include "constraints/constraint_row.h"
#include "constraints/row_key_layouts.h"

namespace taut {

// A 1-dof motor (prismatic or revolute joint) is the bilateral row qdot_i = r with the impulse in
// [-p_max, p_max] (p_max: its max applied impulse per step), r Bullet's motor target
// (btMultiBodyJointMotor::createConstraintRows):
//   r = kp erp (q_target - q) / h + qdot* + kd (qdot_target - qdot*)   (clamped to +-rhs_clamp)
// at the island's v* = qdot*. As a row, C = h (qdot_i - r) (JointSource's convention).
class MultiBodyMotorSource final : public ConstraintSource {
 public:
  explicit MultiBodyMotorSource(int source_id) : key_(kJointRowKey, source_id) {}
  int source_id() const { return key_.source_id(); }

  // Forgets the motors of the last step.
  void Clear() { motors_.clear(); }
  // Adds a motor of `body` (its island body) with id `motor_id` (its index among the world's
  // multibody constraints). Throws InputError for a motor whose joint has not exactly 1 dof.
  void AddMotor(const btMultiBodyJointMotor& motor, const MultiBodyIslandBody* body, int motor_id);
  int num_motors() const { return static_cast<int>(motors_.size()); }

  int AppendIslandRows(const IslandIterate& iterate, std::vector<ConstraintRow>& rows) override;
  // Bilateral rows with finite bounds: never counted as violated (ConstraintRow::violation).
  double CalcIslandViolationSum(const IslandIterate& /*iterate*/) const override { return 0.0; }

 private:
  struct Motor {
    const btMultiBodyJointMotor* motor;
    const MultiBodyIslandBody* body;
    int velocity_index;  // index of the joint's rate in the body's qdot
    int motor_id;
  };
  // Bullet's motor target r at the step start state and v*.
  double CalcTargetRate(const Motor& motor, double h) const;

  RowKeyPacker<2> key_;  // kJointRowKey with this source's id
  std::vector<Motor> motors_;
};

}  // namespace taut
