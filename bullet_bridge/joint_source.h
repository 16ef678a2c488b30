// Bullet joints (btTypedConstraint) inside a deformable island as SQP rows, so a hinge or a
// point-to-point joint on a rigid body that touches a deformable is solved in the same PGS.
#pragma once

#include <BulletDynamics/ConstraintSolver/btContactSolverInfo.h>
#include <BulletDynamics/ConstraintSolver/btTypedConstraint.h>

#include <vector>

#include "bullet_bridge/rigid_island_body.h"
#include "constraints/constraint_row.h"
#include "constraints/row_key_layouts.h"

namespace taut {

// Each joint row of Bullet (getInfo2: J_A, J_B, right-hand side b, bounds lo, hi) asks
// J v = b with lo <= lambda <= hi, where b already holds the joint's position correction
// (erp / h times the error). In the SQP's form C + h J (v - v_k) = 0: C = h (J v_k - b).
// Rows with bounds [0, +inf) are unilateral (joint limits); others bilateral with their bounds.
class JointSource final : public ConstraintSource {
 public:
  // `source_id` < 2^16 (row keys).
  explicit JointSource(int source_id) : key_(kJointRowKey, source_id) {}
  int source_id() const { return key_.source_id(); }

  // Clears the rows (start of a step).
  void Clear() { rows_.clear(); }
  // Evaluates `joint`'s rows at the step start (Bullet linearizes joints once per step); a or b
  // is null for a body that is not coupled (static, kinematic or the fixed body).
  void AddJoint(btTypedConstraint& joint, const RigidIslandBody* a, const RigidIslandBody* b,
                const btContactSolverInfo& info);
  int num_rows() const { return static_cast<int>(rows_.size()); }

  int AppendIslandRows(const IslandIterate& iterate, std::vector<ConstraintRow>& rows) override;
  double CalcIslandViolationSum(const IslandIterate& iterate) const override;

 private:
  // One row of a joint.
  struct JointRow {
    const RigidIslandBody* a;
    const RigidIslandBody* b;
    Vec3 J[4];  // A linear, A angular, B linear, B angular
    double rhs, lo, hi;
    std::uint64_t key;
  };
  // C = h (J v - rhs) at the iterate.
  double CalcC(const IslandIterate& iterate, const JointRow& row) const;
  // Violation of a row at the iterate (see ConstraintRow::violation).
  double CalcViolation(const IslandIterate& iterate, const JointRow& row) const;

  RowKeyPacker<2> key_;  // kJointRowKey with this source's id
  std::vector<JointRow> rows_;
};

}  // namespace taut
