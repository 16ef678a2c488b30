// Contacts of a deformable body's boundary nodes with Bullet rigid objects, as SQP rows: normal
// C = gap >= 0 and two Coulomb friction rows on the disk (docs/math.md §5.5). Static and kinematic
// objects are immovable during the step (one-sided rows); dynamic rigid bodies and the links of
// btMultiBodies in the island take the reaction (two-sided rows: the node against the body's
// surface point; a link's side acts on its multibody's generalized velocity).
#pragma once

#include <BulletCollision/CollisionDispatch/btCollisionObject.h>

#include <vector>

#include "bullet_bridge/multibody_island_body.h"
#include "bullet_bridge/rigid_island_body.h"
#include "constraints/constraint_row.h"
#include "constraints/row_key_layouts.h"
#include "plugin/contact_surface.h"

namespace taut {

// A rigid object a deformable may touch this step.
struct ContactPartner {
  const btCollisionObject* object = nullptr;
  const RigidIslandBody* rigid = nullptr;  // island body of a dynamic rigid body, else null
  // Island body of the multibody whose link collider `object` is (link -1: its base), else null.
  const MultiBodyIslandBody* multibody = nullptr;
  int link = -1;
};

class RigidContactSource final : public ConstraintSource {
 public:
  // `friction` is the body's Coulomb coefficient, combined with each object's by the product
  // (Bullet's default combiner); `margin` [m] is how close a point must be to get rows. The
  // contact points are those of `surface` (usually MakeBodyContactSurface(body.model()));
  // `source_id` < 2^16 (row keys). `restitution` in [0, 1] is the body's Newton restitution,
  // combined with each object's getRestitution() by the product (Bullet's default combiner).
  RigidContactSource(const DeformableBody& body, const ContactSurface& surface, int source_id,
                     double friction, double margin, double restitution = 0.0);

  // Replaces the contact points (e.g. a surface embedded in a hex body: 8-node rows). Points
  // whose nodes are all fixed or kinematic get no rows.
  void set_surface(const ContactSurface& surface);
  // Face contact (DeformableBodySettings::face_contact): besides the points, each surface
  // triangle within the margin of a convex rigid shape gets a normal and two friction rows at
  // their closest points, on the triangle's nodes with the barycentric weights (corners of an
  // embedded surface: their elements' nodes, merged; a triangle whose corners span more than 8
  // nodes keeps point contact). Off by default.
  void set_face_contact(bool on) { face_contact_ = on; }
  bool face_contact() const { return face_contact_; }

  const DeformableBody& body() const { return body_; }
  // The partners to test this step (those whose bounds overlap the body's).
  void set_partners(const std::vector<ContactPartner>& partners) { partners_ = partners; }
  const std::vector<ContactPartner>& partners() const { return partners_; }
  // Immovable partners only (convenience for static scenes and tests).
  void set_objects(const std::vector<const btCollisionObject*>& objects);
  // Approach speed [m/s] above which restitution applies (Bullet's
  // btContactSolverInfo::m_restitutionVelocityThreshold, default 0.2 m/s), so resting contacts,
  // which approach at about g h per step, stay at rest.
  void set_restitution_threshold(double speed) { restitution_threshold_ = speed; }

  int AppendIslandRows(const IslandIterate& iterate, std::vector<ConstraintRow>& rows) override;
  double CalcIslandViolationSum(const IslandIterate& iterate) const override;

 private:
  // Transform of partner o at the iterate (dynamic partners move with their velocity).
  btTransform CalcPartnerTransform(const IslandIterate& iterate, size_t o) const;
  // True when a node of the point moves freely.
  bool Moves(const ContactPoint& point) const;
  // Smallest normal-row C of point i (at p) over the partners at the iterate: the gap, or the
  // restitution C of a closing contact (+inf when no partner is near).
  double CalcPointGap(const IslandIterate& iterate, size_t i, const Vec3& p) const;
  // What the rows against one partner share at an iterate.
  struct PartnerRows {
    int body_index;                        // the deformable's island index
    int rigid_index;                       // the partner's island index, -1 when immovable
    const MultiBodyIslandBody* multibody;  // a multibody link partner (its island index in
    int link;                              // rigid_index), else null
    bool outside_world;  // key fields: the object in no world, keyed by its partner position
    int object_id;
    double mu;           // combined friction
    double restitution;  // combined restitution e
  };
  // Partner o's shared row data at the iterate.
  PartnerRows MakePartnerRows(const IslandIterate& iterate, size_t o) const;
  // The row of direction d (k = 0 normal, 1-2 friction tangents) of `point` (row key `key`)
  // against a partner whose surface point is q (its centre of mass or frame origin at com).
  void FillRow(const PartnerRows& partner, const ContactPoint& point, std::uint64_t key,
               const Vec3& d, const Vec3& q, const Vec3& com, int k, ConstraintRow& row) const;
  // The normal and two friction rows of a contact of `point` (gap, unit normal n from the
  // partner toward the body, partner's surface point q), keyed by `index` and `row_offset`.
  void AppendContactRows(const IslandIterate& iterate, const PartnerRows& partner,
                         const ContactPoint& point, int index, int row_offset, double gap,
                         const Vec3& n, const Vec3& q, const Vec3& com,
                         std::vector<ConstraintRow>& rows) const;
  // The closest points of surface triangle t (its corners at point_x) and a convex shape, when the
  // shape is outside the face within the margin (docs/math.md §5.5, face contact).
  struct FaceContact {
    ContactPoint point;  // the triangle's nodes with the barycentric weights of its closest point
    double gap = 0.0;    // distance from the triangle to the shape's surface (< 0: penetration)
    Vec3 normal;         // unit normal from the shape toward the triangle
    Vec3 q;              // the shape's closest point
  };
  // False when the shape is not convex, lies behind the triangle, is farther than the margin,
  // or is deeper into the triangle than its own collision margin.
  bool FindFaceContact(size_t t, const std::vector<Vec3>& point_x, const btCollisionShape& shape,
                       const btTransform& transform, FaceContact& contact) const;
  // point = sum_k beta_k (corner k's point) over the triangle's corners, equal nodes merged;
  // false when that spans more nodes than a contact point holds (8).
  bool CombineCornerPoints(const Triangle& corners, const Vec3& beta, ContactPoint& point) const;
  // Face rows of every triangle against partner o (AppendIslandRows' second stage).
  void AppendFaceRows(const IslandIterate& iterate, size_t o, const btTransform& transform,
                      std::vector<ConstraintRow>& rows) const;
  // C of a normal row with combined restitution e > 0 (docs/math.md §5.5): when the contact
  // approaches at v* faster than the threshold (approach = -J v*) and would close within the
  // step (gap + h J (v* - v) < 0), C = min(gap, h (J v - e approach)); else the gap.
  double CalcRestitutionC(const IslandIterate& iterate, const ConstraintRow& normal, double gap,
                          double e) const;

  const DeformableBody& body_;
  RowKeyPacker<4> key_;  // kRigidContactRowKey with this source's id
  double friction_;
  double margin_;
  double restitution_;
  double restitution_threshold_ = 0.2;  // [m/s], Bullet's default
  std::vector<ContactPoint> points_;
  std::vector<Triangle> triangles_;               // indices into points_
  mutable std::vector<ConstraintRow> face_rows_;  // CalcIslandViolationSum's face rows (reused)
  mutable std::vector<Vec3> point_x_;             // AppendFaceRows: the points' positions
  bool face_contact_ = false;
  std::vector<ContactPartner> partners_;
};

}  // namespace taut
