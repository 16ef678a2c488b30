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
// J v of a row at the island's velocities: the iterate's, or v* with `star`.
double CalcRowVelocity(const IslandIterate& iterate, const ConstraintRow& row, bool star) {
  double jv = 0.0;
  row.ForEachEntry([&](int body, int block, const Vec3& J) {
    const VecX& v = star ? iterate.body(body).v_star() : iterate.v(body);
    jv += J.dot(v.segment<3>(3 * block));
  });
  return jv;
}
}  // namespace

RigidContactSource::RigidContactSource(const DeformableBody& body, const ContactSurface& surface,
                                       int source_id, double friction, double margin,
                                       double restitution)
    : body_(body),
      key_(kRigidContactRowKey, source_id),
      friction_(friction),
      margin_(margin),
      restitution_(restitution) {
  TAUT_DEMAND(std::isfinite(friction) && friction >= 0.0, "body '", body.name(),
              "': contact friction must be finite and >= 0, got ", friction);
  TAUT_DEMAND(std::isfinite(margin) && margin > 0.0, "body '", body.name(),
              "': contact margin must be finite and > 0 m, got ", margin);
  TAUT_DEMAND(restitution >= 0.0 && restitution <= 1.0, "body '", body.name(),
              "': contact restitution must be in [0, 1], got ", restitution);
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

RigidContactSource::PartnerRows RigidContactSource::MakePartnerRows(const IslandIterate& iterate,
                                                                    size_t o) const {
  const ContactPartner& partner = partners_[o];
  const btCollisionObject& object = *partner.object;
  PartnerRows rows;
  rows.body_index = iterate.IndexOf(&body_);
  rows.rigid_index = partner.rigid != nullptr ? iterate.IndexOf(partner.rigid) : -1;
  // Stable partner id for warm starting: the object's index in the world, or for an object in
  // no world (index -1, e.g. given to set_objects) its position among the partners.
  rows.outside_world = object.getWorldArrayIndex() < 0;
  rows.object_id = rows.outside_world ? static_cast<int>(o) : object.getWorldArrayIndex();
  rows.mu = friction_ * static_cast<double>(object.getFriction());
  rows.restitution = restitution_ * static_cast<double>(object.getRestitution());
  return rows;
}

void RigidContactSource::FillRow(const PartnerRows& partner, size_t i, const Vec3& d, const Vec3& r,
                                 int k, ConstraintRow& row) const {
  const ContactPoint& point = points_[i];
  row.key = key_.Pack(i, partner.outside_world, partner.object_id, k);
  row.body = partner.body_index;
  row.type = RowType::kContact;
  row.num_nodes = point.num_nodes;
  for (int n = 0; n < point.num_nodes; ++n) {
    row.nodes[n] = point.nodes[n];
    row.J[n] = point.weights[n] * d;
  }
  row.friction_of = k;
  row.mu = partner.mu;
  if (partner.rigid_index >= 0) {
    row.body2 = partner.rigid_index;
    row.num_nodes2 = 2;
    row.nodes2[0] = 0;
    row.nodes2[1] = 1;
    row.J2[0] = -d;
    row.J2[1] = -r.cross(d);
  }
}

double RigidContactSource::CalcRestitutionC(const IslandIterate& iterate,
                                            const ConstraintRow& normal, double gap,
                                            double e) const {
  // Newton's rule J v >= -e J v* (Bullet's restitutionCurve), once per contact: only in the step
  // that closes it (the gap predicted at v* is negative), so the bounce happens within one step's
  // travel of the surface, not at the margin.
  const double jv_star = CalcRowVelocity(iterate, normal, true);
  const double approach = -jv_star;
  if (approach <= restitution_threshold_) return gap;
  const double h = iterate.h();
  const double jv = CalcRowVelocity(iterate, normal, false);
  if (gap + h * (jv_star - jv) >= 0.0) return gap;
  return std::min(gap, h * (jv - e * approach));
}

int RigidContactSource::AppendIslandRows(const IslandIterate& iterate,
                                         std::vector<ConstraintRow>& rows) {
  const int before = static_cast<int>(rows.size());
  const VecX& x = iterate.x(iterate.IndexOf(&body_));
  for (size_t o = 0; o < partners_.size(); ++o) {
    const btCollisionObject& object = *partners_[o].object;
    const btTransform transform = CalcPartnerTransform(iterate, o);
    const PartnerRows partner = MakePartnerRows(iterate, o);
    const Vec3 com = ToEigen(transform.getOrigin());
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
      const size_t normal = rows.size();
      for (int k = 0; k < 3; ++k) {
        ConstraintRow& row = rows.emplace_back();
        FillRow(partner, i, d[k], r, k, row);
        row.C = k == 0 ? contact.gap : 0.0;
      }
      if (partner.restitution > 0.0)
        rows[normal].C = CalcRestitutionC(iterate, rows[normal], contact.gap, partner.restitution);
    }
  }
  return static_cast<int>(rows.size()) - before;
}

double RigidContactSource::CalcPointGap(const IslandIterate& iterate, size_t i,
                                        const Vec3& p) const {
  double gap = std::numeric_limits<double>::infinity();
  for (size_t o = 0; o < partners_.size(); ++o) {
    const btTransform transform = CalcPartnerTransform(iterate, o);
    const PointContact contact =
        CalcPointShapeDistance(p, *partners_[o].object->getCollisionShape(), transform, margin_);
    if (!contact.valid) continue;
    double c = contact.gap;
    const double e = restitution_ * static_cast<double>(partners_[o].object->getRestitution());
    if (e > 0.0 && contact.gap < margin_) {
      // The normal row AppendIslandRows emits for this contact, for its restitution C.
      const PartnerRows partner = MakePartnerRows(iterate, o);
      ConstraintRow normal;
      const Vec3 r = p - contact.gap * contact.normal - ToEigen(transform.getOrigin());
      FillRow(partner, i, contact.normal, r, 0, normal);
      c = CalcRestitutionC(iterate, normal, contact.gap, e);
    }
    gap = std::min(gap, c);
  }
  return gap;
}

double RigidContactSource::CalcIslandViolationSum(const IslandIterate& iterate) const {
  const VecX& x = iterate.x(iterate.IndexOf(&body_));
  double sum = 0.0;
  for (size_t i = 0; i < points_.size(); ++i)
    if (Moves(points_[i]))
      sum += std::max(0.0, -CalcPointGap(iterate, i, CalcContactPointPosition(points_[i], x)));
  return sum;
}

}  // namespace taut
