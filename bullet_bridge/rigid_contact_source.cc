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

int RigidContactSource::AppendRows(const VecX& x, int body_index,
                                   std::vector<ConstraintRow>& rows) {
  const int before = static_cast<int>(rows.size());
  for (int node : surface_nodes_) {
    const Vec3 p = x.segment<3>(3 * node);
    for (size_t o = 0; o < objects_.size(); ++o) {
      const btCollisionObject& object = *objects_[o];
      const PointContact contact = CalcPointShapeDistance(
          p, *object.getCollisionShape(), object.getWorldTransform(), margin_);
      if (!contact.valid || contact.gap >= margin_) continue;
      // Normal row C = gap, J = n; then the two tangents (friction on the Coulomb disk).
      Vec3 t[2];
      CalcTangents(contact.normal, t[0], t[1]);
      const double mu = friction_ * static_cast<double>(object.getFriction());
      const std::uint64_t key = key_prefix_ | (static_cast<std::uint64_t>(node) * 64 + o) * 3;
      for (int r = 0; r < 3; ++r) {
        ConstraintRow& row = rows.emplace_back();
        row.key = key + r;
        row.C = r == 0 ? contact.gap : 0.0;
        row.body = body_index;
        row.type = RowType::kContact;
        row.num_nodes = 1;
        row.nodes[0] = node;
        row.J[0] = r == 0 ? contact.normal : t[r - 1];
        row.friction_of = r;
        row.mu = mu;
      }
    }
  }
  return static_cast<int>(rows.size()) - before;
}

double RigidContactSource::CalcNodeGap(const VecX& x, int node) const {
  double gap = std::numeric_limits<double>::infinity();
  for (const btCollisionObject* object : objects_) {
    const PointContact contact = CalcPointShapeDistance(
        x.segment<3>(3 * node), *object->getCollisionShape(), object->getWorldTransform(),
        margin_);
    if (contact.valid) gap = std::min(gap, contact.gap);
  }
  return gap;
}

double RigidContactSource::CalcMaxViolation(const VecX& x) const {
  double violation = 0.0;
  for (int node : surface_nodes_) violation = std::max(violation, -CalcNodeGap(x, node));
  return violation;
}

double RigidContactSource::CalcViolationSum(const VecX& x) const {
  double sum = 0.0;
  for (int node : surface_nodes_) sum += std::max(0.0, -CalcNodeGap(x, node));
  return sum;
}

}  // namespace taut
