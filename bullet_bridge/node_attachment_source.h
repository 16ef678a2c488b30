// Deformable nodes pinned to a dynamic rigid body as bilateral SQP rows
// (docs/architecture.md §4): bone and flesh push and pull each other in the same solve.
#pragma once

#include <vector>

#include "bullet_bridge/rigid_island_body.h"
#include "constraints/constraint_row.h"
#include "constraints/row_key_layouts.h"

namespace taut {

// For every node i with offset r_i in the rigid body's frame and each world axis e:
//   C = e . (x_i - a_i) = 0,  a_i = c + R r_i  (the attachment point at the iterate),
//   J_node = e,  J_lin = -e,  J_ang = -(a_i - c) x e.
class NodeAttachmentSource final : public ConstraintSource {
 public:
  // `local` holds each node's offset in the rigid body's frame. Throws InputError for a node
  // out of range, a size mismatch or a source id beyond 2^16 - 1.
  NodeAttachmentSource(const DeformableBody& body, const RigidIslandBody* rigid,
                       std::vector<int> nodes, std::vector<Vec3> local, int source_id);

  const RigidIslandBody* rigid() const { return rigid_; }
  int AppendIslandRows(const IslandIterate& iterate, std::vector<ConstraintRow>& rows) override;
  double CalcIslandViolationSum(const IslandIterate& iterate) const override;

 private:
  // Attachment points a_i and the centre of mass at the iterate.
  void CalcAnchors(const IslandIterate& iterate, std::vector<Vec3>& anchors, Vec3& com) const;

  const DeformableBody& body_;
  const RigidIslandBody* rigid_;
  std::vector<int> nodes_;
  std::vector<Vec3> local_;
  RowKeyPacker<2> key_;                // kNodeAttachmentRowKey with this source's id
  mutable std::vector<Vec3> anchors_;  // scratch
};

}  // namespace taut
