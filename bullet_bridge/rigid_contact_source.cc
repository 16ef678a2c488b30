#include "bullet_bridge/rigid_contact_source.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "bullet_bridge/eigen_bullet.h"
#include "bullet_bridge/point_shape_distance.h"
#include "plugin/hex_element_model.h"
#include "plugin/tet_element_model.h"

namespace taut {

namespace {
// Boundary nodes of a tet or hex body (all nodes for other models), free ones only.
std::vector<int> CollectSurfaceNodes(const DeformableBody& body) {
  std::vector<int> nodes;
  if (const auto* tets = dynamic_cast<const TetElementModel*>(&body.model())) {
    nodes = CalcBoundaryNodes(tets->mesh());
  } else {
    for (int i = 0; i < body.num_nodes(); ++i) nodes.push_back(i);
  }
  nodes.erase(std::remove_if(nodes.begin(), nodes.end(),
                             [&](int i) { return body.node_kind(i) != NodeKind::kFree; }),
              nodes.end());
  return nodes;
}

// Two unit tangents orthogonal to n.
void CalcTangents(const Vec3& n, Vec3& t1, Vec3& t2) {
  t1 = (std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(n).normalized();
  t2 = n.cross(t1);
}
}  // namespace

RigidContactSource::RigidContactSource(const DeformableBody& body, int source_id, double friction,
                                       double margin)
    : body_(body),
      key_prefix_(static_cast<std::uint64_t>(source_id) << 48),
      friction_(friction),
      margin_(margin),
      surface_nodes_(CollectSurfaceNodes(body)) {
  TAUT_DEMAND(std::isfinite(friction) && friction >= 0.0, "body '", body.name(),
              "': contact friction must be finite and >= 0, got ", friction);
  TAUT_DEMAND(std::isfinite(margin) && margin > 0.0, "body '", body.name(),
              "': contact margin must be finite and > 0 m, got ", margin);
}

void RigidContactSource::set_objects(const std::vector<const btCollisionObject*>& objects) {
  partners_.clear();
  for (const btCollisionObject* object : objects) partners_.push_back({object, nullptr});
}

btTransform RigidContactSource::CalcPartnerTransform(const IslandIterate& iterate,
                                                     size_t o) const {
  const ContactPartner& partner = partners_[o];
  if (partner.rigid == nullptr) return partner.object->getWorldTransform();
  return partner.rigid->PredictTransform(iterate.h(), iterate.v(iterate.IndexOf(partner.rigid)));
}

int RigidContactSource::AppendIslandRows(const IslandIterate& iterate,
                                         std::vector<ConstraintRow>& rows) {
  const int before = static_cast<int>(rows.size());
  const int body_index = iterate.IndexOf(&body_);
  const VecX& x = iterate.x(body_index);
  for (size_t o = 0; o < partners_.size(); ++o) {
    const ContactPartner& partner = partners_[o];
    const btCollisionObject& object = *partner.object;
    const btTransform transform = CalcPartnerTransform(iterate, o);
    const int rigid_index = partner.rigid != nullptr ? iterate.IndexOf(partner.rigid) : -1;
    const Vec3 com = ToEigen(transform.getOrigin());
    const double mu = friction_ * static_cast<double>(object.getFriction());
    // Stable partner id for warm starting: the object's index in the world.
    const std::uint64_t object_id = static_cast<std::uint64_t>(object.getWorldArrayIndex()) & 4095;
    for (int node : surface_nodes_) {
      const Vec3 p = x.segment<3>(3 * node);
      const PointContact contact =
          CalcPointShapeDistance(p, *object.getCollisionShape(), transform, margin_);
      if (!contact.valid || contact.gap >= margin_) continue;
      // Normal row C = gap, J = n on the node; then the two tangents (friction on the Coulomb
      // disk). A dynamic partner's surface point q = p - gap n moves with v + w x (q - com), so
      // its side is J_lin = -d, J_ang = -(q - com) x d for each direction d.
      Vec3 d[3];
      d[0] = contact.normal;
      CalcTangents(contact.normal, d[1], d[2]);
      const Vec3 r = p - contact.gap * contact.normal - com;
      const std::uint64_t key =
          key_prefix_ | ((static_cast<std::uint64_t>(node) * 4096 + object_id) * 3);
      for (int k = 0; k < 3; ++k) {
        ConstraintRow& row = rows.emplace_back();
        row.key = key + k;
        row.C = k == 0 ? contact.gap : 0.0;
        row.body = body_index;
        row.type = RowType::kContact;
        row.num_nodes = 1;
        row.nodes[0] = node;
        row.J[0] = d[k];
        row.friction_of = k;
        row.mu = mu;
        if (rigid_index >= 0) {
          row.body2 = rigid_index;
          row.num_nodes2 = 2;
          row.nodes2[0] = 0;
          row.nodes2[1] = 1;
          row.J2[0] = -d[k];
          row.J2[1] = -r.cross(d[k]);
        }
      }
    }
  }
  return static_cast<int>(rows.size()) - before;
}

double RigidContactSource::CalcNodeGap(const IslandIterate& iterate, const VecX& x,
                                       int node) const {
  double gap = std::numeric_limits<double>::infinity();
  for (size_t o = 0; o < partners_.size(); ++o) {
    const PointContact contact =
        CalcPointShapeDistance(x.segment<3>(3 * node), *partners_[o].object->getCollisionShape(),
                               CalcPartnerTransform(iterate, o), margin_);
    if (contact.valid) gap = std::min(gap, contact.gap);
  }
  return gap;
}

double RigidContactSource::CalcIslandMaxViolation(const IslandIterate& iterate) const {
  const VecX& x = iterate.x(iterate.IndexOf(&body_));
  double violation = 0.0;
  for (int node : surface_nodes_) violation = std::max(violation, -CalcNodeGap(iterate, x, node));
  return violation;
}

double RigidContactSource::CalcIslandViolationSum(const IslandIterate& iterate) const {
  const VecX& x = iterate.x(iterate.IndexOf(&body_));
  double sum = 0.0;
  for (int node : surface_nodes_) sum += std::max(0.0, -CalcNodeGap(iterate, x, node));
  return sum;
}

}  // namespace taut
