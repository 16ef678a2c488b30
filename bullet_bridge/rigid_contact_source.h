// Contacts of a deformable body's boundary nodes with Bullet rigid objects, as SQP rows: normal
// C = gap >= 0 and two Coulomb friction rows on the disk (docs/math.md §5.5). Static and kinematic
// objects are immovable during the step (one-sided rows); dynamic rigid bodies of the island
// take the reaction (two-sided rows: the node against the body's surface point).
#pragma once

#include <BulletCollision/CollisionDispatch/btCollisionObject.h>

#include <vector>

#include "bullet_bridge/rigid_island_body.h"
#include "constraints/constraint_row.h"
#include "constraints/row_key_layouts.h"
#include "plugin/contact_surface.h"

namespace taut {

// A rigid object a deformable may touch this step.
struct ContactPartner {
  const btCollisionObject* object = nullptr;
  const RigidIslandBody* rigid = nullptr;  // island body of a dynamic rigid body, else null
};

class RigidContactSource final : public ConstraintSource {
 public:
  // `friction` is the body's Coulomb coefficient, combined with each object's by the product
  // (Bullet's default combiner); `margin` [m] is how close a point must be to get rows. The
  // contact points are those of `surface` (usually MakeBodyContactSurface(body.model()));
  // `source_id` < 2^16 (row keys).
  RigidContactSource(const DeformableBody& body, const ContactSurface& surface, int source_id,
                     double friction, double margin);

  // Replaces the contact points (e.g. a surface embedded in a hex body: 8-node rows). Points
  // whose nodes are all fixed or kinematic get no rows.
  void set_surface(const ContactSurface& surface);

  const DeformableBody& body() const { return body_; }
  // The partners to test this step (those whose bounds overlap the body's).
  void set_partners(const std::vector<ContactPartner>& partners) { partners_ = partners; }
  const std::vector<ContactPartner>& partners() const { return partners_; }
  // Immovable partners only (convenience for static scenes and tests).
  void set_objects(const std::vector<const btCollisionObject*>& objects);

  int AppendIslandRows(const IslandIterate& iterate, std::vector<ConstraintRow>& rows) override;
  double CalcIslandViolationSum(const IslandIterate& iterate) const override;

 private:
  // Transform of partner o at the iterate (dynamic partners move with their velocity).
  btTransform CalcPartnerTransform(const IslandIterate& iterate, size_t o) const;
  // True when a node of the point moves freely.
  bool Moves(const ContactPoint& point) const;
  // Smallest gap of point p over the partners at the iterate (+inf when none is within the margin).
  double CalcPointGap(const IslandIterate& iterate, const Vec3& p) const;

  const DeformableBody& body_;
  RowKeyPacker<4> key_;  // kRigidContactRowKey with this source's id
  double friction_;
  double margin_;
  std::vector<ContactPoint> points_;
  std::vector<ContactPartner> partners_;
};

}  // namespace taut
