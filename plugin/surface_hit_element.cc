#include "plugin/surface_hit_element.h"

#include <Eigen/LU>
#include <algorithm>
#include <limits>

namespace taut {
namespace internal {

Eigen::Vector4d CalcTetBarycentric(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c,
                                   const Vec3& d) {
  // [b-a c-a d-a] (l1 l2 l3)^T = p - a, l0 = 1 - l1 - l2 - l3.
  Mat3 edges;
  edges << b - a, c - a, d - a;
  Eigen::Vector4d l;
  const Eigen::FullPivLU<Mat3> lu(edges);
  if (!lu.isInvertible())
    return Eigen::Vector4d::Constant(std::numeric_limits<double>::quiet_NaN());
  l.tail<3>() = lu.solve(p - a);
  l[0] = 1.0 - l.tail<3>().sum();
  return l;
}

}  // namespace internal

namespace {

// Preference of a candidate element (compared lexicographically, larger is better).
struct Score {
  bool contains = false;  // a tet containing the hit
  int corners = 0;        // triangle corner points whose nodes the element holds
  double minus_distance = -std::numeric_limits<double>::infinity();  // -|centroid - hit|
  bool operator<(const Score& o) const {
    if (contains != o.contains) return !contains;
    if (corners != o.corners) return corners < o.corners;
    return minus_distance < o.minus_distance;
  }
};

// True when element e holds every node of point p.
bool HoldsPoint(const int* nodes, int k, const ContactPoint& p) {
  for (int a = 0; a < p.num_nodes; ++a)
    if (std::find(nodes, nodes + k, p.nodes[a]) == nodes + k) return false;
  return true;
}

// The score of element e for `hit`; corners = 0 means e is no candidate.
Score ScoreElement(const ElementModel& model, const VecX& x, const ContactPoint* corners[3], int e,
                   const Vec3& hit) {
  const int k = model.nodes_per_element();
  const int* nodes = model.element_nodes(e);
  Score score;
  for (int c = 0; c < 3; ++c) score.corners += HoldsPoint(nodes, k, *corners[c]) ? 1 : 0;
  if (score.corners == 0) return score;
  Vec3 centroid = Vec3::Zero();
  for (int a = 0; a < k; ++a) centroid += x.segment<3>(3 * nodes[a]);
  score.minus_distance = -(centroid / k - hit).norm();
  if (k == 4) {
    const auto node = [&](int a) -> Vec3 { return x.segment<3>(3 * nodes[a]); };
    const Eigen::Vector4d l = internal::CalcTetBarycentric(hit, node(0), node(1), node(2), node(3));
    score.contains = l.allFinite() && l.minCoeff() >= -1e-9;
  }
  return score;
}

}  // namespace

int FindHitElement(const ElementModel& model, const VecX& x, const ContactSurface& surface,
                   int triangle, const Vec3& hit) {
  TAUT_DEMAND(triangle >= 0 && triangle < static_cast<int>(surface.triangles.size()),
              "FindHitElement: triangle ", triangle, " out of range [0, ", surface.triangles.size(),
              ")");
  const Triangle& t = surface.triangles[triangle];
  const ContactPoint* corners[3] = {&surface.points[t[0]], &surface.points[t[1]],
                                    &surface.points[t[2]]};
  int best = -1;
  Score best_score;
  for (int e = 0; e < model.num_elements(); ++e) {
    const Score score = ScoreElement(model, x, corners, e, hit);
    if (score.corners > 0 && (best < 0 || best_score < score)) {
      best = e;
      best_score = score;
    }
  }
  return best;
}

}  // namespace taut
