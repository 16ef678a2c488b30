#include "bullet_bridge/node_attachment_source.h"

#include <algorithm>
#include <cmath>

#include "bullet_bridge/eigen_bullet.h"

namespace taut {

NodeAttachmentSource::NodeAttachmentSource(const DeformableBody& body, const RigidIslandBody* rigid,
                                           std::vector<int> nodes, std::vector<Vec3> local,
                                           int source_id)
    : body_(body),
      rigid_(rigid),
      nodes_(std::move(nodes)),
      local_(std::move(local)),
      key_(kNodeAttachmentRowKey, source_id) {
  TAUT_DEMAND(rigid != nullptr, "body '", body.name(), "': attachment to a null rigid body");
  TAUT_DEMAND(nodes_.size() == local_.size(), "body '", body.name(), "': ", nodes_.size(),
              " attached nodes but ", local_.size(), " offsets");
  for (int node : nodes_)
    TAUT_DEMAND(node >= 0 && node < body.num_nodes(), "body '", body.name(), "': attached node ",
                node, " out of range [0, ", body.num_nodes(), ")");
  anchors_.resize(nodes_.size());
}

void NodeAttachmentSource::CalcAnchors(const IslandIterate& iterate, std::vector<Vec3>& anchors,
                                       Vec3& com) const {
  const btTransform t = rigid_->PredictTransform(iterate.h(), iterate.v(iterate.IndexOf(rigid_)));
  com = ToEigen(t.getOrigin());
  for (size_t k = 0; k < nodes_.size(); ++k) anchors[k] = ToEigen(t * ToBullet(local_[k]));
}

int NodeAttachmentSource::AppendIslandRows(const IslandIterate& iterate,
                                           std::vector<ConstraintRow>& rows) {
  const int body_index = iterate.IndexOf(&body_);
  const int rigid_index = iterate.IndexOf(rigid_);
  const VecX& x = iterate.x(body_index);
  Vec3 com;
  CalcAnchors(iterate, anchors_, com);
  for (size_t k = 0; k < nodes_.size(); ++k) {
    const int node = nodes_[k];
    const Vec3 gap = x.segment<3>(3 * node) - anchors_[k];
    const Vec3 r = anchors_[k] - com;
    for (int axis = 0; axis < 3; ++axis) {
      const Vec3 e = Vec3::Unit(axis);
      ConstraintRow& row = rows.emplace_back();
      row.key = key_.Pack(k, axis);
      row.C = gap[axis];
      row.type = RowType::kJoint;
      row.bilateral = true;
      row.body = body_index;
      row.num_nodes = 1;
      row.nodes[0] = node;
      row.J[0] = e;
      row.body2 = rigid_index;
      row.num_nodes2 = 2;
      row.nodes2[0] = 0;
      row.nodes2[1] = 1;
      row.J2[0] = -e;
      row.J2[1] = -r.cross(e);
    }
  }
  return static_cast<int>(3 * nodes_.size());
}

double NodeAttachmentSource::CalcIslandViolationSum(const IslandIterate& iterate) const {
  const VecX& x = iterate.x(iterate.IndexOf(&body_));
  Vec3 com;
  CalcAnchors(iterate, anchors_, com);
  double sum = 0.0;
  for (size_t k = 0; k < nodes_.size(); ++k)
    sum += (x.segment<3>(3 * nodes_[k]) - anchors_[k]).cwiseAbs().sum();
  return sum;
}

}  // namespace taut
