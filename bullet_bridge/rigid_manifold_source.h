// Bullet's rigid-rigid contacts inside a deformable island as SQP rows, so they are solved in the
// same PGS sweeps as the deformables' limits and contacts (docs/architecture.md §4).
#pragma once

#include <BulletCollision/NarrowPhaseCollision/btPersistentManifold.h>
#include <BulletDynamics/ConstraintSolver/btContactSolverInfo.h>

#include <array>
#include <vector>

#include "bullet_bridge/rigid_island_body.h"
#include "constraints/constraint_row.h"
#include "constraints/row_key_layouts.h"

namespace taut {

// One contact point of a Bullet manifold between bodies A and B (either may be immovable).
struct RigidContactPoint {
  const RigidIslandBody* a = nullptr;  // null: immovable (static or kinematic)
  const RigidIslandBody* b = nullptr;
  Vec3 ra, rb;      // contact points relative to the centres of mass [m]
  Vec3 normal;      // from B to A (Bullet's normalWorldOnB)
  Vec3 tangent[2];  // friction directions
  double distance;  // signed separation at the step start [m], < 0 penetrating
  double bounce;    // restitution target of the normal relative velocity [m/s], >= 0
  double friction;  // combined Coulomb coefficient
  std::array<std::uint64_t, 3> keys;  // identity for warm starting: normal, two friction rows
};

// Rows of the contact points: normal J v >= max(-d/h, bounce) (d scaled by erp when
// penetrating), written in the SQP's form C + h J (v - v_k) >= 0 with C = h (J v_k - target);
// two friction rows on the Coulomb disk of each normal row.
class RigidManifoldSource final : public ConstraintSource {
 public:
  // `source_id` < 2^16 (row keys).
  explicit RigidManifoldSource(int source_id) : key_(kRigidManifoldRowKey, source_id) {}
  int source_id() const { return key_.source_id(); }

  // Clears the points (start of a step).
  void Clear() { points_.clear(); }
  // Adds the points of `manifold` within its processing threshold; bodies not coupled by the
  // island (static, kinematic) are passed as null. Restitution applies when the approach speed
  // at v* exceeds info.m_restitutionVelocityThreshold (Bullet's rule); penetration is corrected
  // by info.m_erp2 per step.
  void AddManifold(const btPersistentManifold& manifold, const RigidIslandBody* a,
                   const RigidIslandBody* b, const btContactSolverInfo& info);
  int num_points() const { return static_cast<int>(points_.size()); }

  int AppendIslandRows(const IslandIterate& iterate, std::vector<ConstraintRow>& rows) override;
  double CalcIslandViolationSum(const IslandIterate& iterate) const override;

 private:
  // J v of direction d at point p of the iterate (relative velocity of A's point minus B's).
  double CalcRelativeVelocity(const IslandIterate& iterate, const RigidContactPoint& p,
                              const Vec3& d) const;
  // Normal-row value C = h (J v - target) at the iterate.
  double CalcNormalC(const IslandIterate& iterate, const RigidContactPoint& p) const;

  RowKeyPacker<4> key_;  // kRigidManifoldRowKey with this source's id
  double erp_ = 0.2;
  std::vector<RigidContactPoint> points_;
};

}  // namespace taut
