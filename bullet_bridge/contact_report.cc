#include "bullet_bridge/contact_report.h"

#include <algorithm>

#include "bullet_bridge/eigen_bullet.h"
#include "bullet_bridge/rigid_island_body.h"
#include "constraints/row_key_layouts.h"
#include "constraints/strain_limit_rows.h"

namespace taut {

namespace {
// The dynamic rigid body behind an island body, or null.
const RigidIslandBody* AsRigid(const IslandBody* body) {
  return dynamic_cast<const RigidIslandBody*>(body);
}

// sum_n J_n over side A: the row's direction d times the point's weight sum (1 for contact
// points, whose weights sum to 1), so an impulse lambda moves side A by sum_n J_n lambda.
Vec3 SumSideA(const ConstraintRow& row) {
  Vec3 sum = Vec3::Zero();
  for (int n = 0; n < row.num_nodes; ++n) sum += row.J[n];
  return sum;
}

// p = sum_n w_n x_n / sum_n w_n with w_n = J_n . d (side A's J_n = w_n d for a contact row).
Vec3 CalcRowPoint(const ConstraintRow& row, const VecX& x, const Vec3& d) {
  Vec3 p = Vec3::Zero();
  double weight = 0.0;
  for (int n = 0; n < row.num_nodes; ++n) {
    const double w = row.J[n].dot(d);
    p += w * x.segment<3>(3 * row.nodes[n]);
    weight += w;
  }
  return p / weight;
}

// The entry of `object` in forces.wrenches (added on first use).
RigidBodyWrench& FindWrench(SubstepForces& forces, const btCollisionObject* object) {
  for (RigidBodyWrench& wrench : forces.wrenches)
    if (wrench.object == object) return wrench;
  RigidBodyWrench& wrench = forces.wrenches.emplace_back();
  wrench.object = object;
  wrench.rigid = btRigidBody::upcast(object);
  return wrench;
}

// Adds side B's generalized impulse J_B^T lambda / h of a row on a dynamic rigid body: block 0
// (linear) to the force [N], block 1 (angular, about the predicted centre of mass) to the torque.
void AddRigidSide(const ConstraintRow& row, double lambda, double h, RigidBodyWrench& wrench) {
  for (int n = 0; n < row.num_nodes2; ++n)
    (row.nodes2[n] == 0 ? wrench.force : wrench.torque) += row.J2[n] * (lambda / h);
}

// The world's object of a rigid contact key (null for an object in no world).
const btCollisionObject* FindPartnerObject(std::uint64_t key,
                                           const btCollisionObjectArray& objects) {
  const auto fields = UnpackRowKeyPayload(kRigidContactRowKey, RowKeyPayload(key));
  const bool outside_world = fields[1] != 0;
  const int index = static_cast<int>(fields[2]);
  if (outside_world || index >= objects.size()) return nullptr;
  return objects[index];
}

// Stage: a deformable pair's contact (kDeformableContactRowKey: side A's point on side B's
// triangle) and its mirror on side B.
void AppendDeformablePair(const ConstraintRow& row, const DeformableBody* partner,
                          DeformableContactPoint contact, SubstepForces& forces) {
  const auto fields = UnpackRowKeyPayload(kDeformableContactRowKey, RowKeyPayload(row.key));
  contact.point = static_cast<int>(fields[1]);
  contact.partner_body = partner;
  DeformableContactPoint mirror = contact;
  mirror.body = partner;
  mirror.partner_body = contact.body;
  mirror.point = mirror.node = -1;
  mirror.triangle = static_cast<int>(fields[2]);
  mirror.normal = -contact.normal;
  mirror.friction_impulse = -contact.friction_impulse;
  mirror.force = -contact.force;
  forces.contacts.push_back(contact);
  forces.contacts.push_back(mirror);
}

// Stage: a rigid partner's contact (kRigidContactRowKey: a contact point, or a face contact on a
// triangle) of normal row c, and the wrench it puts on that rigid object.
void AppendRigidPartner(const IslandRows& rows, const VecX& lambda, int c,
                        const RigidIslandBody* dynamic, const btCollisionObjectArray& objects,
                        DeformableContactPoint contact, SubstepForces& forces) {
  const auto fields = UnpackRowKeyPayload(kRigidContactRowKey, RowKeyPayload(rows[c].key));
  (fields[3] >= kRigidFaceRowOffset ? contact.triangle : contact.point) =
      static_cast<int>(fields[0]);
  contact.partner_object =
      dynamic != nullptr ? dynamic->rigid() : FindPartnerObject(rows[c].key, objects);
  forces.contacts.push_back(contact);
  if (contact.partner_object == nullptr) return;
  RigidBodyWrench& wrench = FindWrench(forces, contact.partner_object);
  wrench.num_contacts++;
  if (dynamic != nullptr) {
    // The solve's own side B: J_lin = -d, J_ang = -(q - com) x d.
    for (int k = 0; k <= 2 && c + k < rows.size() && (k == 0 || rows[c + k].friction_of == k); ++k)
      AddRigidSide(rows[c + k], lambda[c + k], forces.h, wrench);
    return;
  }
  // Immovable partner: -F at its surface point q = p - gap n, about its centre of mass.
  const btTransform& transform = contact.partner_object->getWorldTransform();
  const Vec3 com = ToEigen(wrench.rigid != nullptr ? wrench.rigid->getCenterOfMassPosition()
                                                   : transform.getOrigin());
  const Vec3 q = contact.position - contact.gap * contact.normal;
  wrench.force -= contact.force;
  wrench.torque -= (q - com).cross(contact.force);
}

// Stage: the contact of normal row c (tangent rows c + 1, c + 2) on side A's body, its mirror on
// a deformable side B, and the wrench on a rigid side B.
void AppendContact(const std::vector<IslandBody*>& bodies, const IslandRows& rows,
                   const VecX& lambda, int c, const btCollisionObjectArray& objects,
                   SubstepForces& forces) {
  const ConstraintRow& row = rows[c];
  const double h = forces.h;
  DeformableContactPoint contact;
  const Vec3 sum = SumSideA(row);
  const double weight = sum.norm();
  contact.normal = sum / weight;
  contact.normal_impulse = lambda[c];
  for (int k = 1; k <= 2 && c + k < rows.size() && rows[c + k].friction_of == k; ++k)
    contact.friction_impulse += SumSideA(rows[c + k]) / weight * lambda[c + k];
  contact.gap = row.C;
  if (contact.normal_impulse == 0.0 && contact.friction_impulse.isZero(0.0) && contact.gap > 0.0)
    return;  // within the margin, never touched: not a contact of this step
  contact.body = bodies[row.body]->deformable();
  contact.mu = row.mu;
  contact.position = CalcRowPoint(row, rows.x(row.body), contact.normal);
  contact.node = row.num_nodes == 1 ? row.nodes[0] : -1;
  contact.force = (contact.normal_impulse * contact.normal + contact.friction_impulse) / h;
  const IslandBody* side_b = row.body2 >= 0 ? bodies[row.body2] : nullptr;
  const DeformableBody* partner = side_b != nullptr ? side_b->deformable() : nullptr;
  if (partner != nullptr) {
    AppendDeformablePair(row, partner, contact, forces);
    return;
  }
  AppendRigidPartner(rows, lambda, c, AsRigid(side_b), objects, contact, forces);
}

// Stage: a strain- or energy-limit row with its multiplier.
void AppendLimit(const std::vector<IslandBody*>& bodies, const ConstraintRow& row, double lambda,
                 SubstepForces& forces) {
  LimitRowMultiplier& limit = forces.limits.emplace_back();
  limit.body = bodies[row.body]->deformable();
  limit.C = row.C;
  limit.multiplier = lambda;
  if (row.type == RowType::kStrainLimit) {
    const StrainLimitKey key = StrainLimitKey::Unpack(RowKeyPayload(row.key));
    limit.element = key.element;
    limit.kind = key.axis == kStrainFloorAxis     ? LimitRowKind::kStrainFloor
                 : key.bound == StrainBound::kMin ? LimitRowKind::kStrainMin
                                                  : LimitRowKind::kStrainMax;
    limit.axis = key.axis;
    limit.principal_axis = key.principal_axis;
  } else {
    limit.element =
        static_cast<int>(UnpackRowKeyPayload(kEnergyLimitRowKey, RowKeyPayload(row.key))[0]);
    limit.kind = LimitRowKind::kEnergy;
  }
  for (int n = 0; n < row.num_nodes; ++n)
    limit.max_nodal_force =
        std::max(limit.max_nodal_force, row.J[n].norm() * std::abs(lambda) / forces.h);
}
}  // namespace

void SubstepForces::Clear(double step) {
  h = step;
  contacts.clear();
  wrenches.clear();
  limits.clear();
}

void AppendIslandForces(const std::vector<IslandBody*>& bodies, const IslandRows& rows,
                        const VecX& lambda, const btCollisionObjectArray& objects,
                        SubstepForces& forces) {
  TAUT_DEMAND(forces.h > 0.0, "AppendIslandForces: substep h must be > 0 s, got ", forces.h);
  TAUT_DEMAND(lambda.size() == rows.size(), "AppendIslandForces: ", lambda.size(),
              " multipliers for ", rows.size(), " rows");
  for (int c = 0; c < rows.size(); ++c) {
    const ConstraintRow& row = rows[c];
    const bool deformable_a = bodies[row.body]->deformable() != nullptr;
    if (!deformable_a) continue;  // rigid-rigid manifold and Bullet joint rows
    if (IsLimitRow(row)) {
      AppendLimit(bodies, row, lambda[c], forces);
    } else if (row.type == RowType::kContact && row.friction_of == 0) {
      AppendContact(bodies, rows, lambda, c, objects, forces);
    } else if (row.type == RowType::kJoint && row.body2 >= 0) {
      // A node attachment to a dynamic rigid body: its side B is the body's generalized impulse.
      if (const RigidIslandBody* rigid = AsRigid(bodies[row.body2]))
        AddRigidSide(row, lambda[c], forces.h, FindWrench(forces, rigid->rigid()));
    }
  }
}

}  // namespace taut
