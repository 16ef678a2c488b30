// Contact between two deformable bodies: the contact points of each body against the surface
// triangles of the other (vertex-triangle), as normal rows C = gap >= 0 with two Coulomb
// friction rows on the disk (docs/math.md §5.5), coupling both bodies in one island. Also the
// self-contact of one body: its boundary nodes against its own boundary triangles, in the same
// rows.
#pragma once

#include <memory>
#include <vector>

#include "constraints/constraint_row.h"
#include "constraints/point_spatial_hash.h"
#include "constraints/row_key_layouts.h"
#include "constraints/self_contact_search.h"
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
  // Self-contact of `body` (docs/math.md §5.5, self-contact): the points of `surface` (single
  // nodes with node triangles, e.g. MakeBodyContactSurface(body.model())) against its own
  // triangles, the admissible pairs of SelfContactSearch (rest exclusion, facing, margin). Both
  // sides of a row are the body; keys have direction 0. `friction` is the combined coefficient
  // (the world uses the body's squared, the product rule of a pair).
  DeformableContactSource(const DeformableBody& body, const ContactSurface& surface, int source_id,
                          double friction, double margin);

  // True for the self-contact of one body.
  bool is_self_contact() const { return self_ != nullptr; }
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
  // Every point-triangle contact within the margin at positions xa, xb (self-contact: xa).
  void FindHits(const VecX& xa, const VecX& xb) const;
  // The pair's contacts, both directions: per point of one body the nearest triangle of the other
  // within the margin, the candidates from a spatial hash of the points.
  void FindPairHits(const VecX& xa, const VecX& xb) const;

  const DeformableBody& a_;
  const DeformableBody& b_;
  ContactSurface surfaces_[2];
  RowKeyPacker<4> key_;  // kDeformableContactRowKey with this source's id
  double friction_, margin_;
  std::unique_ptr<SelfContactSearch> self_;  // self-contact only
  mutable std::vector<Hit> hits_;            // scratch of the last FindHits
  mutable std::vector<SelfContactSearch::Hit> self_hits_;
  // Scratch of FindPairHits: the points' positions and their hash, the nearest hit per point.
  mutable std::vector<Vec3> point_positions_;
  mutable PointSpatialHash hash_;
  mutable std::vector<Hit> best_;
  mutable std::vector<double> best_distance_;
};

namespace internal {
// Nearest point of triangle (a, b, c) to p as barycentric weights (Ericson, Real-Time Collision
// Detection, 5.1.5).
Vec3 CalcNearestTrianglePoint(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);
}  // namespace internal

}  // namespace taut
