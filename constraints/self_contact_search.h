// The candidate search of self-contact (docs/math.md §5.5, self-contact): the boundary points of
// one deformable body against its own boundary triangles, without the O(P T) loop of all pairs.
#pragma once

#include <cstdint>
#include <vector>

#include "constraints/point_spatial_hash.h"
#include "plugin/contact_surface.h"
#include "plugin/deformable_body.h"

namespace taut {

// For every boundary point i, the nearest admissible triangle t within the margin at node
// positions x. A pair (i, t) is admissible when
//  - rest exclusion: the rest distance from X_i to t is at least kRestExclusion margins. This
//    removes the triangles around i, their surface neighbours within that distance and the far
//    side of parts thinner than it, fixed once at construction: a body at rest (or moved rigidly)
//    has no self-contact candidates;
//  - facing: n_i . n_t < 0 at x, with n_i the area-weighted normal of the triangles around i
//    and n_t the triangle's outward normal, so the two surface patches face each other (a fold
//    pressed shut); neighbours on a compressed or bent surface, whose normals agree, are not
//    contacts;
//  - moving: a node of the point or of the triangle is free;
//  - within the margin: |p_i - q| < margin (q the nearest point of t).
// Broadphase: the points in a spatial hash (constraints/point_spatial_hash.h), rebuilt per call;
// each triangle visits the points in its bounds grown by the margin.
class SelfContactSearch {
 public:
  // Rest exclusion radius in contact margins.
  static constexpr double kRestExclusion = 2.0;

  // A point i against triangle t: nearest point q = sum_k beta_k x_{t_k}, outward unit normal
  // n_t, gap = n_t . (p_i - q) [m].
  struct Hit {
    int point, triangle;
    Vec3 normal, beta;
    double gap;
  };

  // `surface`: single-node points with node triangles (MakeBodyContactSurface(body.model()));
  // its rest positions are the model's rest positions. `margin` [m] > 0. Throws InputError for
  // a surface with embedded points or non-node triangles.
  SelfContactSearch(const DeformableBody& body, const ContactSurface& surface, double margin);

  // The hits at node positions x (3N), one per point with an admissible triangle, by point.
  void FindHits(const VecX& x, std::vector<Hit>& hits) const;
  // Number of (point, triangle) pairs the rest exclusion removes.
  int num_excluded_pairs() const { return static_cast<int>(excluded_.size()); }
  // True when the rest exclusion removes the pair (point i, triangle t).
  bool IsExcluded(int i, int t) const;

 private:
  // Positions of the points at node positions x (positions_).
  void CalcPointPositions(const VecX& x) const;
  // Calls visit(i, t, v0, v1, v2) for every point i inside triangle t's bounds grown by `reach`
  // (triangles in order; a point may be visited twice for one triangle).
  template <typename Visit>
  void ForEachNearPair(const VecX& x, double reach, Visit&& visit) const;
  // The rest-exclusion pairs, sorted by point (excluded_start_, excluded_).
  void FindExcludedPairs(const VecX& rest);
  // Area-weighted normals of the points at positions x (point_normals_).
  void CalcPointNormals(const VecX& x) const;
  // True when a node of point i or of triangle t is free.
  bool Moves(int i, int t) const;

  const DeformableBody& body_;
  std::vector<int> node_of_point_;
  std::vector<Triangle> triangles_;  // indices into the points
  double margin_;
  std::vector<int> excluded_start_;  // (num_points + 1): CSR offsets into excluded_
  std::vector<int> excluded_;        // excluded triangles of each point, ascending
  // Scratch of the last call.
  mutable std::vector<Vec3> positions_, point_normals_;
  mutable PointSpatialHash hash_;  // of positions_
  mutable std::vector<Hit> best_;  // nearest admissible triangle per point (triangle -1: none)
  mutable std::vector<double> best_distance_;  // its distance [m] (the margin when none)
};

}  // namespace taut
