#include "constraints/deformable_contact_source.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace taut {

namespace internal {

Vec3 CalcNearestTrianglePoint(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  // Voronoi regions of the vertices, edges and face, in that order.
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return Vec3(1, 0, 0);
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return Vec3(0, 1, 0);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    const double v = d1 / (d1 - d3);
    return Vec3(1 - v, v, 0);
  }
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return Vec3(0, 0, 1);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    const double w = d2 / (d2 - d6);
    return Vec3(1 - w, 0, w);
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return Vec3(0, 1 - w, w);
  }
  const double denom = 1.0 / (va + vb + vc);
  const double v = vb * denom, w = vc * denom;
  return Vec3(1 - v - w, v, w);
}

}  // namespace internal

namespace {
// Node of a triangle corner (node triangles: every corner point is one node).
int CornerNode(const ContactSurface& surface, int triangle, int corner) {
  return surface.points[surface.triangles[triangle][corner]].nodes[0];
}
}  // namespace

DeformableContactSource::DeformableContactSource(const DeformableBody& a,
                                                 const ContactSurface& surface_a,
                                                 const DeformableBody& b,
                                                 const ContactSurface& surface_b, int source_id,
                                                 double friction, double margin)
    : a_(a),
      b_(b),
      surfaces_{surface_a, surface_b},
      key_(kDeformableContactRowKey, source_id),
      friction_(friction),
      margin_(margin) {
  TAUT_DEMAND(&a != &b, "body '", a.name(), "': deformable contact needs two different bodies");
  TAUT_DEMAND(std::isfinite(friction) && friction >= 0.0, "bodies '", a.name(), "' and '", b.name(),
              "': contact friction must be finite and >= 0, got ", friction);
  TAUT_DEMAND(std::isfinite(margin) && margin > 0.0, "bodies '", a.name(), "' and '", b.name(),
              "': contact margin must be finite and > 0 m, got ", margin);
}

DeformableContactSource::DeformableContactSource(const DeformableBody& body,
                                                 const ContactSurface& surface, int source_id,
                                                 double friction, double margin)
    : a_(body),
      b_(body),
      surfaces_{surface, surface},
      key_(kDeformableContactRowKey, source_id),
      friction_(friction),
      margin_(margin) {
  TAUT_DEMAND(std::isfinite(friction) && friction >= 0.0, "body '", body.name(),
              "': self-contact friction must be finite and >= 0, got ", friction);
  self_ = std::make_unique<SelfContactSearch>(body, surface, margin);
}

void DeformableContactSource::FindHits(const VecX& xa, const VecX& xb) const {
  if (self_ == nullptr) {
    FindPairHits(xa, xb);
    return;
  }
  self_->FindHits(xa, self_hits_);
  hits_.clear();
  for (const SelfContactSearch::Hit& hit : self_hits_)
    hits_.push_back({0, hit.point, hit.triangle, hit.normal, hit.beta, hit.gap});
}

void DeformableContactSource::FindPairHits(const VecX& xa, const VecX& xb) const {
  hits_.clear();
  const VecX* x[2] = {&xa, &xb};
  for (int direction = 0; direction < 2; ++direction) {
    const ContactSurface& points = surfaces_[direction];
    const ContactSurface& target = surfaces_[1 - direction];
    if (!target.node_triangles || target.triangles.empty() || points.points.empty()) continue;
    const VecX& xt = *x[1 - direction];
    const auto corner = [&](std::size_t t, int k) -> Vec3 {
      return xt.segment<3>(3 * CornerNode(target, static_cast<int>(t), k));
    };
    point_positions_.resize(points.points.size());
    for (size_t i = 0; i < points.points.size(); ++i)
      point_positions_[i] = CalcContactPointPosition(points.points[i], *x[direction]);
    hash_.Build(point_positions_, CalcHashCellSize(target.triangles, margin_, corner));
    // Per point the nearest triangle within the margin, triangles in order (the first of equal
    // distances).
    best_.assign(points.points.size(), Hit{direction, -1, -1, Vec3::Zero(), Vec3::Zero(), 0.0});
    best_distance_.assign(points.points.size(), margin_);
    for (size_t t = 0; t < target.triangles.size(); ++t) {
      const Vec3 v0 = corner(t, 0), v1 = corner(t, 1), v2 = corner(t, 2);
      const Vec3 lo = v0.cwiseMin(v1).cwiseMin(v2).array() - margin_;
      const Vec3 hi = v0.cwiseMax(v1).cwiseMax(v2).array() + margin_;
      hash_.ForEachPointInBox(lo, hi, [&](int i) {
        const Vec3& p = point_positions_[i];
        const Vec3 beta = internal::CalcNearestTrianglePoint(p, v0, v1, v2);
        const Vec3 q = beta[0] * v0 + beta[1] * v1 + beta[2] * v2;
        const double distance = (p - q).norm();
        if (distance >= best_distance_[i]) return;
        const Vec3 normal = (v1 - v0).cross(v2 - v0);
        if (normal.squaredNorm() == 0.0) return;  // degenerate triangle
        best_distance_[i] = distance;
        Hit& hit = best_[i];
        hit.point = i;
        hit.triangle = static_cast<int>(t);
        hit.beta = beta;
        hit.normal = normal.normalized();
        hit.gap = hit.normal.dot(p - q);
      });
    }
    for (const Hit& hit : best_)
      if (hit.triangle >= 0) hits_.push_back(hit);
  }
}

int DeformableContactSource::AppendIslandRows(const IslandIterate& iterate,
                                              std::vector<ConstraintRow>& rows) {
  const int ia = iterate.IndexOf(&a_), ib = iterate.IndexOf(&b_);
  FindHits(iterate.x(ia), iterate.x(ib));
  const int before = static_cast<int>(rows.size());
  const int index[2] = {ia, ib};
  for (const Hit& hit : hits_) {
    const ContactSurface& points = surfaces_[hit.direction];
    const ContactSurface& target = surfaces_[1 - hit.direction];
    const ContactPoint& point = points.points[hit.point];
    Vec3 d[3];
    d[0] = hit.normal;
    CalcContactTangents(hit.normal, d[1], d[2]);
    for (int k = 0; k < CountContactRows(friction_); ++k) {
      ConstraintRow& row = rows.emplace_back();
      row.key = key_.Pack(hit.direction, hit.point, hit.triangle, k);
      row.C = k == 0 ? hit.gap : 0.0;
      row.type = RowType::kContact;
      row.friction_of = k;
      row.mu = friction_;
      row.body = index[hit.direction];
      row.num_nodes = point.num_nodes;
      for (int n = 0; n < point.num_nodes; ++n) {
        row.nodes[n] = point.nodes[n];
        row.J[n] = point.weights[n] * d[k];
      }
      row.body2 = index[1 - hit.direction];
      row.num_nodes2 = 3;
      for (int c = 0; c < 3; ++c) {
        row.nodes2[c] = CornerNode(target, hit.triangle, c);
        row.J2[c] = -hit.beta[c] * d[k];
      }
    }
  }
  return static_cast<int>(rows.size()) - before;
}

double DeformableContactSource::CalcIslandViolationSum(const IslandIterate& iterate) const {
  FindHits(iterate.x(iterate.IndexOf(&a_)), iterate.x(iterate.IndexOf(&b_)));
  double sum = 0.0;
  for (const Hit& hit : hits_) sum += std::max(0.0, -hit.gap);
  return sum;
}

}  // namespace taut
