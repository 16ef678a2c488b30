#include "bullet_bridge/rigid_contact_source.h"

#include <BulletCollision/CollisionShapes/btTriangleShape.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkEpa2.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "bullet_bridge/eigen_bullet.h"
#include "bullet_bridge/point_shape_distance.h"
#include "constraints/deformable_contact_source.h"
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
  triangles_ = surface.triangles;
  for (const Triangle& t : triangles_)
    for (int corner : t)
      TAUT_DEMAND(corner >= 0 && corner < static_cast<int>(points_.size()), "body '", body_.name(),
                  "': contact triangle corner ", corner, " out of range [0, ", points_.size(), ")");
}

void RigidContactSource::set_objects(const std::vector<const btCollisionObject*>& objects) {
  partners_.clear();
  for (const btCollisionObject* object : objects) partners_.push_back({object, nullptr});
}

btTransform RigidContactSource::CalcPartnerTransform(const IslandIterate& iterate, size_t o) const {
  const ContactPartner& partner = partners_[o];
  if (partner.multibody != nullptr)
    return partner.multibody->PredictColliderTransform(
        partner.link, iterate.h(), iterate.v(iterate.IndexOf(partner.multibody)));
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
  rows.multibody = partner.multibody;
  rows.link = partner.link;
  if (partner.multibody != nullptr) rows.rigid_index = iterate.IndexOf(partner.multibody);
  // Stable partner id for warm starting: the object's index in the world, or for an object in
  // no world (index -1, e.g. given to set_objects) its position among the partners.
  rows.outside_world = object.getWorldArrayIndex() < 0;
  rows.object_id = rows.outside_world ? static_cast<int>(o) : object.getWorldArrayIndex();
  rows.mu = friction_ * static_cast<double>(object.getFriction());
  rows.restitution = restitution_ * static_cast<double>(object.getRestitution());
  return rows;
}

void RigidContactSource::FillRow(const PartnerRows& partner, const ContactPoint& point,
                                 std::uint64_t key, const Vec3& d, const Vec3& q, const Vec3& com,
                                 int k, ConstraintRow& row) const {
  row.key = key;
  row.body = partner.body_index;
  row.type = RowType::kContact;
  row.num_nodes = point.num_nodes;
  for (int n = 0; n < point.num_nodes; ++n) {
    row.nodes[n] = point.nodes[n];
    row.J[n] = point.weights[n] * d;
  }
  row.friction_of = k;
  row.mu = partner.mu;
  if (partner.multibody != nullptr) {
    // The link's surface point q moves with J_q qdot: its side is -d^T J_q (the multibody's
    // contact Jacobian, btMultiBody::fillContactJacobianMultiDof).
    row.body2 = partner.rigid_index;
    row.num_nodes2 = partner.multibody->FillPointRowEntries(partner.link, q, d, -1.0,
                                                            row.nodes2.data(), row.J2.data());
  } else if (partner.rigid_index >= 0) {
    const Vec3 r = q - com;
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

void RigidContactSource::AppendContactRows(const IslandIterate& iterate, const PartnerRows& partner,
                                           const ContactPoint& point, int index, int row_offset,
                                           double gap, const Vec3& n, const Vec3& q,
                                           const Vec3& com,
                                           std::vector<ConstraintRow>& rows) const {
  // Normal row C = gap, J = w_k n on the point's nodes; then, when mu > 0, the two tangents
  // (friction on the Coulomb disk). A dynamic partner's surface point q moves with v + w x (q -
  // com), so its side is J_lin = -d, J_ang = -(q - com) x d for each direction d.
  Vec3 d[3];
  d[0] = n;
  CalcContactTangents(n, d[1], d[2]);
  const size_t normal = rows.size();
  for (int k = 0; k < CountContactRows(partner.mu); ++k) {
    ConstraintRow& row = rows.emplace_back();
    const std::uint64_t key =
        key_.Pack(index, partner.outside_world, partner.object_id, row_offset + k);
    FillRow(partner, point, key, d[k], q, com, k, row);
    row.C = k == 0 ? gap : 0.0;
  }
  if (partner.restitution > 0.0)
    rows[normal].C = CalcRestitutionC(iterate, rows[normal], gap, partner.restitution);
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
      const Vec3 q = p - contact.gap * contact.normal;  // the partner's surface point
      AppendContactRows(iterate, partner, point, static_cast<int>(i), 0, contact.gap,
                        contact.normal, q, com, rows);
    }
    if (face_contact()) AppendFaceRows(iterate, o, transform, rows);
  }
  return static_cast<int>(rows.size()) - before;
}

bool RigidContactSource::CombineCornerPoints(const Triangle& corners, const Vec3& beta,
                                             ContactPoint& point) const {
  // sum_k beta_k sum_n w_kn x_kn with equal nodes merged (corners of an embedded surface share
  // their element's nodes).
  point.num_nodes = 0;
  for (int k = 0; k < 3; ++k) {
    const ContactPoint& corner = points_[corners[k]];
    for (int j = 0; j < corner.num_nodes; ++j) {
      const double w = beta[k] * corner.weights[j];
      if (w == 0.0) continue;
      int n = 0;
      while (n < point.num_nodes && point.nodes[n] != corner.nodes[j]) ++n;
      if (n == point.num_nodes) {
        if (n == static_cast<int>(point.nodes.size())) return false;  // too many nodes
        point.nodes[n] = corner.nodes[j];
        point.weights[n] = 0.0;
        ++point.num_nodes;
      }
      point.weights[n] += w;
    }
  }
  return true;
}

bool RigidContactSource::FindFaceContact(size_t t, const std::vector<Vec3>& point_x,
                                         const btCollisionShape& shape,
                                         const btTransform& transform, FaceContact& contact) const {
  if (!shape.isConvex()) return false;  // planes, meshes and compounds: points only
  const Triangle& corners = triangles_[t];
  const Vec3& a = point_x[corners[0]];
  const Vec3& b = point_x[corners[1]];
  const Vec3& c = point_x[corners[2]];
  Vec3 n = (b - a).cross(c - a);  // outward (the surface is wound outward)
  const double norm = n.norm();
  if (!(norm > 0.0)) return false;
  n /= norm;
  // A shape whose centre lies behind the face touches another part of the body.
  if (n.dot(ToEigen(transform.getOrigin()) - a) <= 0.0) return false;
  // Closest points of the triangle and the shape's core (Bullet's GJK; the shape is its core
  // grown by its collision margin, e.g. a capsule's segment by its radius).
  const auto& convex = static_cast<const btConvexShape&>(shape);
  btTriangleShape triangle(ToBullet(a), ToBullet(b), ToBullet(c));
  triangle.setMargin(0);
  btGjkEpaSolver2::sResults result;
  if (!btGjkEpaSolver2::Distance(&triangle, btTransform::getIdentity(), &convex, transform,
                                 ToBullet(n), result))
    return false;  // the core reaches the triangle: deeper than the margin, points only
  const double core_distance = result.distance;
  const Vec3 normal = ToEigen(result.normal);  // unit, from the shape's core to the triangle
  // Only a shape outside the face pushes it inward.
  if (!(core_distance > 0.0) || normal.dot(n) >= 0.0) return false;
  const double shape_margin = convex.getMargin();
  contact.gap = core_distance - shape_margin;
  if (contact.gap >= margin_) return false;
  const Vec3 p = ToEigen(result.witnesses[0]);  // on the triangle
  const Vec3 weights = internal::CalcNearestTrianglePoint(p, a, b, c);
  if (!CombineCornerPoints(corners, weights, contact.point)) return false;
  contact.normal = normal;
  contact.q = ToEigen(result.witnesses[1]) + shape_margin * normal;  // on the shape's surface
  return true;
}

void RigidContactSource::AppendFaceRows(const IslandIterate& iterate, size_t o,
                                        const btTransform& transform,
                                        std::vector<ConstraintRow>& rows) const {
  const btCollisionShape& shape = *partners_[o].object->getCollisionShape();
  if (!shape.isConvex()) return;
  const VecX& x = iterate.x(iterate.IndexOf(&body_));
  const PartnerRows partner = MakePartnerRows(iterate, o);
  const Vec3 com = ToEigen(transform.getOrigin());
  // Only triangles whose bounds meet the shape's bounds grown by the margin.
  btVector3 lo, hi;
  shape.getAabb(transform, lo, hi);
  const Vec3 grow = Vec3::Constant(margin_);
  const Eigen::AlignedBox3d bounds(ToEigen(lo) - grow, ToEigen(hi) + grow);
  // Each point once (a surface vertex is a corner of about six triangles).
  point_x_.resize(points_.size());
  for (size_t i = 0; i < points_.size(); ++i) point_x_[i] = CalcContactPointPosition(points_[i], x);
  FaceContact contact;
  for (size_t t = 0; t < triangles_.size(); ++t) {
    Eigen::AlignedBox3d box;
    for (int corner : triangles_[t]) box.extend(point_x_[corner]);
    if (!bounds.intersects(box) || !FindFaceContact(t, point_x_, shape, transform, contact))
      continue;
    if (!Moves(contact.point)) continue;
    AppendContactRows(iterate, partner, contact.point, static_cast<int>(t), kRigidFaceRowOffset,
                      contact.gap, contact.normal, contact.q, com, rows);
  }
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
      const Vec3 q = p - contact.gap * contact.normal;
      const std::uint64_t key = key_.Pack(i, partner.outside_world, partner.object_id, 0);
      FillRow(partner, points_[i], key, contact.normal, q, ToEigen(transform.getOrigin()), 0,
              normal);
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
  if (!face_contact()) return sum;
  // Face contacts: the gaps of the rows AppendFaceRows emits (restitution C included).
  face_rows_.clear();
  for (size_t o = 0; o < partners_.size(); ++o)
    AppendFaceRows(iterate, o, CalcPartnerTransform(iterate, o), face_rows_);
  for (const ConstraintRow& row : face_rows_) sum += row.violation();
  return sum;
}

}  // namespace taut
