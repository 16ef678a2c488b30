#include "bullet_bridge/rigid_manifold_source.h"

#include <algorithm>
#include <cmath>

#include "bullet_bridge/eigen_bullet.h"

namespace taut {

namespace {
// The island velocity of body `r` (zero velocity for an immovable body).
Vec3 PointVelocity(const IslandIterate& iterate, const RigidIslandBody* r, const Vec3& rel) {
  if (r == nullptr) return Vec3::Zero();
  const VecX& v = iterate.v(iterate.IndexOf(r));
  return v.head<3>() + Vec3(v.tail<3>()).cross(rel);
}
// A stable id of a collision object (its broadphase unique id).
int ObjectId(const btCollisionObject* object) {
  const btBroadphaseProxy* proxy = object->getBroadphaseHandle();
  return proxy != nullptr ? proxy->m_uniqueId : 0;
}
}  // namespace

void RigidManifoldSource::AddManifold(const btPersistentManifold& manifold,
                                      const RigidIslandBody* a, const RigidIslandBody* b,
                                      const btContactSolverInfo& info) {
  erp_ = static_cast<double>(info.m_erp2);
  const btCollisionObject* object_a = manifold.getBody0();
  const btCollisionObject* object_b = manifold.getBody1();
  const Vec3 com_a = ToEigen(object_a->getWorldTransform().getOrigin());
  const Vec3 com_b = ToEigen(object_b->getWorldTransform().getOrigin());
  const double threshold = static_cast<double>(manifold.getContactProcessingThreshold());
  for (int i = 0; i < manifold.getNumContacts(); ++i) {
    const btManifoldPoint& point = manifold.getContactPoint(i);
    if (static_cast<double>(point.getDistance()) > threshold) continue;
    RigidContactPoint p;
    p.a = a;
    p.b = b;
    p.ra = ToEigen(point.getPositionWorldOnA()) - com_a;
    p.rb = ToEigen(point.getPositionWorldOnB()) - com_b;
    p.normal = ToEigen(point.m_normalWorldOnB).normalized();
    CalcContactTangents(p.normal, p.tangent[0], p.tangent[1]);
    p.distance = static_cast<double>(point.getDistance());
    p.friction = static_cast<double>(point.m_combinedFriction);
    // Approach speed at v* (Bullet's solver also measures it after external impulses).
    const Vec3 va = a != nullptr
                        ? RigidIslandBody::CalcPointVelocity(a->v_star(), com_a + p.ra, com_a)
                        : Vec3::Zero();
    const Vec3 vb = b != nullptr
                        ? RigidIslandBody::CalcPointVelocity(b->v_star(), com_b + p.rb, com_b)
                        : Vec3::Zero();
    const double approach = -p.normal.dot(va - vb);
    p.bounce = approach > static_cast<double>(info.m_restitutionVelocityThreshold)
                   ? static_cast<double>(point.m_combinedRestitution) * approach
                   : 0.0;
    for (int k = 0; k < 3; ++k) p.keys[k] = key_.Pack(ObjectId(object_a), ObjectId(object_b), i, k);
    points_.push_back(p);
  }
}

double RigidManifoldSource::CalcRelativeVelocity(const IslandIterate& iterate,
                                                 const RigidContactPoint& p, const Vec3& d) const {
  return d.dot(PointVelocity(iterate, p.a, p.ra) - PointVelocity(iterate, p.b, p.rb));
}

double RigidManifoldSource::CalcNormalC(const IslandIterate& iterate,
                                        const RigidContactPoint& p) const {
  // Target: J v >= max(-d/h, bounce), with the penetration part scaled by erp (d < 0).
  const double h = iterate.h();
  const double correction = p.distance >= 0.0 ? p.distance : erp_ * p.distance;
  const double target = std::max(-correction / h, p.bounce);
  return h * (CalcRelativeVelocity(iterate, p, p.normal) - target);
}

int RigidManifoldSource::AppendIslandRows(const IslandIterate& iterate,
                                          std::vector<ConstraintRow>& rows) {
  const int before = static_cast<int>(rows.size());
  for (const RigidContactPoint& p : points_) {
    const int ia = p.a != nullptr ? iterate.IndexOf(p.a) : -1;
    const int ib = p.b != nullptr ? iterate.IndexOf(p.b) : -1;
    const double c = CalcNormalC(iterate, p);
    const Vec3 d[3] = {p.normal, p.tangent[0], p.tangent[1]};
    for (int k = 0; k < CountContactRows(p.friction); ++k) {
      ConstraintRow& row = rows.emplace_back();
      row.key = p.keys[k];
      row.C = k == 0 ? c : 0.0;
      row.type = RowType::kRigidContact;
      row.friction_of = k;
      row.mu = p.friction;
      // J = [d, ra x d] on A and [-d, -(rb x d)] on B; an immovable side is left out.
      if (ia >= 0) {
        row.body = ia;
        row.num_nodes = 2;
        row.nodes[0] = 0;
        row.nodes[1] = 1;
        row.J[0] = d[k];
        row.J[1] = p.ra.cross(d[k]);
      }
      if (ib >= 0) {
        int& body = ia >= 0 ? row.body2 : row.body;
        int& count = ia >= 0 ? row.num_nodes2 : row.num_nodes;
        auto& nodes = ia >= 0 ? row.nodes2 : row.nodes;
        auto& J = ia >= 0 ? row.J2 : row.J;
        body = ib;
        count = 2;
        nodes[0] = 0;
        nodes[1] = 1;
        J[0] = -d[k];
        J[1] = -p.rb.cross(d[k]);
      }
    }
  }
  return static_cast<int>(rows.size()) - before;
}

double RigidManifoldSource::CalcIslandViolationSum(const IslandIterate& iterate) const {
  double sum = 0.0;
  for (const RigidContactPoint& p : points_) sum += std::max(0.0, -CalcNormalC(iterate, p));
  return sum;
}

}  // namespace taut
