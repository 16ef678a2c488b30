#include "bullet_bridge/rigid_contact_source.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "bullet_bridge/eigen_bullet.h"
#include "bullet_bridge/point_shape_distance.h"
#include "plugin/hex_element_model.h"
#include "plugin/tet_element_model.h"

namespace taut {

RigidContactSource::RigidContactSource(const DeformableBody& body, const ContactSurface& surface,
                                       int source_id, double friction, double margin)
    : body_(body), key_(kRigidContactRowKey, source_id), friction_(friction), margin_(margin) {
  TAUT_DEMAND(std::isfinite(friction) && friction >= 0.0, "body '", body.name(),
              "': contact friction must be finite and >= 0, got ", friction);
  TAUT_DEMAND(std::isfinite(margin) && margin > 0.0, "body '", body.name(),
              "': contact margin must be finite and > 0 m, got ", margin);
  set_surface(surface);
}

bool RigidContactSource::Moves(const ContactPoint& point) const {
  for (int k = 0; k < point.num_nodes; ++k)
    if (body_.node_kind(point.nodes[k]) == NodeKind::kFree) return true;
  return false;
}

void RigidContactSource::set_surface(const ContactSurface& surface) {
  for (const ContactPoint& p : surface.points)
    for (int k = 0; k < p.num_nodes; ++k)
      TAUT_DEMAND(p.nodes[k] >= 0 && p.nodes[k] < body_.num_nodes(), "body '", body_.name(),
                  "': contact point node ", p.nodes[k], " out of range [0, ", body_.num_nodes(),
                  ")");
  points_ = surface.points;
}

void RigidContactSource::set_objects(const std::vector<const btCollisionObject*>& objects) {
  partners_.clear();
  for (const btCollisionObject* object : objects) partners_.push_back({object, nullptr});
}

btTransform RigidContactSource::CalcPartnerTransform(const IslandIterate& iterate, size_t o) const {
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
    // Stable partner id for warm starting: the object's index in the world, or for an object in
    // no world (index -1, e.g. given to set_objects) its position among the partners.
    const bool outside_world = object.getWorldArrayIndex() < 0;
    const int object_id = outside_world ? static_cast<int>(o) : object.getWorldArrayIndex();
    for (size_t i = 0; i < points_.size(); ++i) {
      const ContactPoint& point = points_[i];
      if (!Moves(point)) continue;  // fixed or kinematic: nothing to solve
      const Vec3 p = CalcContactPointPosition(point, x);
      const PointContact contact =
          CalcPointShapeDistance(p, *object.getCollisionShape(), transform, margin_);
      if (!contact.valid || contact.gap >= margin_) continue;
      // Normal row C = gap, J = w_k n on the point's nodes; then the two tangents (friction on
      // the Coulomb disk). A dynamic partner's surface point q = p - gap n moves with v + w x (q -
      // com), so its side is J_lin = -d, J_ang = -(q - com) x d for each direction d.
      Vec3 d[3];
      d[0] = contact.normal;
      CalcContactTangents(contact.normal, d[1], d[2]);
      const Vec3 r = p - contact.gap * contact.normal - com;
      for (int k = 0; k < 3; ++k) {
        ConstraintRow& row = rows.emplace_back();
        row.key = key_.Pack(i, outside_world, object_id, k);
        row.C = k == 0 ? contact.gap : 0.0;
        row.body = body_index;
        row.type = RowType::kContact;
        row.num_nodes = point.num_nodes;
        for (int n = 0; n < point.num_nodes; ++n) {
          row.nodes[n] = point.nodes[n];
          row.J[n] = point.weights[n] * d[k];
        }
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

double RigidContactSource::CalcPointGap(const IslandIterate& iterate, const Vec3& p) const {
  double gap = std::numeric_limits<double>::infinity();
  for (size_t o = 0; o < partners_.size(); ++o) {
    const PointContact contact = CalcPointShapeDistance(
        p, *partners_[o].object->getCollisionShape(), CalcPartnerTransform(iterate, o), margin_);
    if (contact.valid) gap = std::min(gap, contact.gap);
  }
  return gap;
}

double RigidContactSource::CalcIslandViolationSum(const IslandIterate& iterate) const {
  const VecX& x = iterate.x(iterate.IndexOf(&body_));
  double sum = 0.0;
  for (const ContactPoint& point : points_)
    if (Moves(point))
      sum += std::max(0.0, -CalcPointGap(iterate, CalcContactPointPosition(point, x)));
  return sum;
}

}  // namespace taut
