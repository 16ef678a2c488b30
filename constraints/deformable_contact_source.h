// Contact between two deformable bodies: the contact points of each body against the surface
// triangles of the other (vertex-triangle), as normal rows C = gap >= 0 with two Coulomb
// friction rows on the disk (docs/math.md §5.5), coupling both bodies in one island.
#pragma once

#include <vector>

#include "constraints/constraint_row.h"
#include "constraints/row_key_layouts.h"
#include "plugin/contact_surface.h"

namespace taut {

// For a point p of one body and its nearest surface triangle (a, b, c) of the other, within the
// margin: q = beta_a x_a + beta_b x_b + beta_c x_c is the nearest point and n the triangle's
// outward unit normal; C = n . (p - q), J = w_k n on the point's nodes, -beta_i n on the
// triangle's nodes (n frozen at the iterate). A point found inside the other body deeper than
// the margin is not seen (contacts are caught before they get that deep).
class DeformableContactSource final : public ConstraintSource {
 public:
  // Triangles of a surface whose corners are not single nodes (embedded surfaces) are not used
  // as targets (its points still touch the other body's triangles). `friction` is the combined
  // Coulomb coefficient; `margin` [m] > 0; `source_id` < 2^16 (row keys).
  DeformableContactSource(const DeformableBody& a, const ContactSurface& surface_a,
                          const DeformableBody& b, const ContactSurface& surface_b, int source_id,
                          double friction, double margin);

  const DeformableBody& body_a() const { return a_; }
  const DeformableBody& body_b() const { return b_; }
  int AppendIslandRows(const IslandIterate& iterate, std::vector<ConstraintRow>& rows) override;
  double CalcIslandViolationSum(const IslandIterate& iterate) const override;

 private:
  // One point-triangle contact found at the iterate.
  struct Hit {
    int direction;  // 0: points of A against triangles of B; 1: the reverse
    int point, triangle;
    Vec3 normal, beta;
    double gap;
  };
  // Every point-triangle contact within the margin at positions xa, xb.
  void FindHits(const VecX& xa, const VecX& xb) const;
  // Nearest triangle of `surface` (positions x) to p within the margin; false when none.
  bool FindNearestTriangle(const ContactSurface& surface, const VecX& x, const Vec3& p,
                           Hit& hit) const;

  const DeformableBody& a_;
  const DeformableBody& b_;
  ContactSurface surfaces_[2];
  RowKeyPacker<4> key_;  // kDeformableContactRowKey with this source's id
  double friction_, margin_;
  mutable std::vector<Hit> hits_;  // scratch of the last FindHits
};

namespace internal {
// Nearest point of triangle (a, b, c) to p as barycentric weights (Ericson, Real-Time Collision
// Detection, 5.1.5).
Vec3 CalcNearestTrianglePoint(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);
}  // namespace internal

}  // namespace taut
