// Point-vs-shape signed distance: analytic for the simple shapes, GJK/EPA for other convex shapes,
// closest triangle for concave meshes.
#include "bullet_bridge/point_shape_distance.h"

#include <BulletCollision/BroadphaseCollision/btBroadphaseProxy.h>
#include <BulletCollision/CollisionShapes/btBoxShape.h>
#include <BulletCollision/CollisionShapes/btCapsuleShape.h>
#include <BulletCollision/CollisionShapes/btCompoundShape.h>
#include <BulletCollision/CollisionShapes/btConcaveShape.h>
#include <BulletCollision/CollisionShapes/btConvexPolyhedron.h>
#include <BulletCollision/CollisionShapes/btCylinderShape.h>
#include <BulletCollision/CollisionShapes/btSphereShape.h>
#include <BulletCollision/CollisionShapes/btStaticPlaneShape.h>
#include <BulletCollision/CollisionShapes/btTriangleCallback.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkEpa2.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "bullet_bridge/eigen_bullet.h"

namespace taut {
namespace {

constexpr double kTiny = 1e-12;

// A result in the shape's local frame, before the transform to world.
struct LocalContact {
  double gap;
  Vec3 normal;
  Vec3 closest;
};

// Unit vector e_axis.
Vec3 Axis(int axis) { return Vec3::Unit(axis); }

// Plane n·x = c: gap = n·p − c, closest = p − gap n.
LocalContact CalcPlane(const Vec3& p, const btStaticPlaneShape& plane) {
  const Vec3 n = ToEigen(plane.getPlaneNormal()).normalized();
  const double gap = n.dot(p) - static_cast<double>(plane.getPlaneConstant());
  return {gap, n, p - gap * n};
}

// Ball of radius r around segment s(t) = t e_axis, t ∈ [−half, half] (half = 0: sphere).
// gap = |p − s*| − r with s* the closest segment point; normal = (p − s*)/|p − s*|.
LocalContact CalcRoundedSegment(const Vec3& p, int axis, double half, double r) {
  Vec3 s = Vec3::Zero();
  s[axis] = std::clamp(p[axis], -half, half);
  const Vec3 d = p - s;
  const double dist = d.norm();
  // On the axis the normal is not unique; pick a radial direction.
  const Vec3 n = dist > kTiny ? Vec3(d / dist) : Axis((axis + 1) % 3);
  return {dist - r, n, s + r * n};
}

// Sharp box |x_i| ≤ h_i. Outside: closest = clamp(p); inside: the nearest face, gap = max(|p|−h).
LocalContact CalcBox(const Vec3& p, const Vec3& h) {
  const Vec3 q = p.cwiseAbs() - h;
  if ((q.array() > 0.0).any()) {
    const Vec3 closest = p.cwiseMax(-h).cwiseMin(h);
    const Vec3 d = p - closest;
    const double dist = d.norm();
    return {dist, d / dist, closest};
  }
  int k = 0;
  const double gap = q.maxCoeff(&k);
  const double sign = p[k] >= 0.0 ? 1.0 : -1.0;
  Vec3 closest = p;
  closest[k] = sign * h[k];
  return {gap, sign * Axis(k), closest};
}

// Sharp cylinder ρ ≤ r, |z| ≤ half along `axis`: a 2D box in (ρ, z).
LocalContact CalcCylinder(const Vec3& p, int axis, double r, double half) {
  const double z = p[axis];
  Vec3 radial = p;
  radial[axis] = 0.0;
  const double rho = radial.norm();
  const Vec3 u = rho > kTiny ? Vec3(radial / rho) : Axis((axis + 1) % 3);
  const Vec3 e = Axis(axis);
  const double q_r = rho - r;
  const double q_z = std::abs(z) - half;
  if (q_r > 0.0 || q_z > 0.0) {
    const Vec3 closest = std::min(rho, r) * u + std::clamp(z, -half, half) * e;
    const Vec3 d = p - closest;
    const double dist = d.norm();
    return {dist, d / dist, closest};
  }
  if (q_r > q_z) return {q_r, u, r * u + z * e};
  const double sign = z >= 0.0 ? 1.0 : -1.0;
  return {q_z, sign * e, radial + sign * half * e};
}

// The radial half extent of a Bullet cylinder with up axis `axis` (btCylinderShape::getRadius).
int CylinderRadiusIndex(int axis) { return axis == 0 ? 1 : 0; }

// Keeps the nearest triangle of a concave shape (local frame). Ties (shared edges and vertices)
// go to the triangle whose plane is most aligned with p − q, which gives the right sign at
// convex and concave edges.
class ClosestTriangleCallback : public btTriangleCallback {
 public:
  explicit ClosestTriangleCallback(const Vec3& p) : p_(p) {}

  // Closest point of one triangle; replaces the best if nearer or equally near and more aligned.
  void processTriangle(btVector3* triangle, int /*part*/, int /*index*/) override {
    const Vec3 a = ToEigen(triangle[0]), b = ToEigen(triangle[1]), c = ToEigen(triangle[2]);
    const Vec3 n = (b - a).cross(c - a);
    const double area2 = n.norm();
    if (area2 <= kTiny * (b - a).squaredNorm()) return;  // degenerate
    const Vec3 unit_n = n / area2;
    const Vec3 q = internal::CalcClosestPointOnTriangle(p_, a, b, c);
    const Vec3 d = p_ - q;
    const double dist = d.norm();
    const double align = dist > kTiny ? std::abs(unit_n.dot(d)) / dist : 1.0;
    const double tol = 1e-12 * (1.0 + dist);
    if (found_ && (dist > best_dist_ + tol || (dist > best_dist_ - tol && align <= best_align_))) {
      return;
    }
    found_ = true;
    best_dist_ = dist;
    best_align_ = align;
    best_q_ = q;
    best_n_ = unit_n;
  }

  // Signed result: sign of n·(p − q) of the chosen triangle; normal points out of its front side.
  bool Result(LocalContact* out) const {
    if (!found_) return false;
    const Vec3 d = p_ - best_q_;
    const double sign = best_n_.dot(d) >= 0.0 ? 1.0 : -1.0;
    const Vec3 n = best_dist_ > kTiny ? Vec3(sign * d / best_dist_) : best_n_;
    *out = {sign * best_dist_, n, best_q_};
    return true;
  }

 private:
  Vec3 p_;
  bool found_ = false;
  double best_dist_ = std::numeric_limits<double>::infinity();
  double best_align_ = 0.0;
  Vec3 best_q_{0, 0, 0};
  Vec3 best_n_{0, 0, 1};
};

// Local result -> world PointContact.
PointContact ToWorld(const LocalContact& c, const btTransform& transform) {
  PointContact out;
  out.gap = c.gap;
  out.normal = ToEigen(transform.getBasis() * ToBullet(c.normal));
  out.point_on_shape = ToEigen(transform * ToBullet(c.closest));
  out.valid = true;
  return out;
}

// Euclidean distance from p to the shape's world AABB (0 inside).
double CalcAabbDistance(const Vec3& p, const btCollisionShape& shape, const btTransform& t) {
  btVector3 lo, hi;
  shape.getAabb(t, lo, hi);
  const Vec3 below = (ToEigen(lo) - p).cwiseMax(0.0);
  const Vec3 above = (p - ToEigen(hi)).cwiseMax(0.0);
  return (below + above).norm();
}

}  // namespace

namespace internal {

// Real-Time Collision Detection (Ericson) §5.1.5 region tests, written from the barycentric
// conditions: vertex regions, edge regions, then the face.
Vec3 CalcClosestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return a;
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return a + d1 / (d1 - d3) * ab;
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return a + d2 / (d2 - d6) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
  }
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

// btGjkEpaSolver2::SignedDistance with a zero-radius probe sphere: outside it returns
// |w1 − w0| − margin (margin-expanded surface), inside the EPA depth with margins.
PointContact CalcGjkPointDistance(const Vec3& point, const btConvexShape& shape,
                                  const btTransform& transform) {
  btGjkEpaSolver2::sResults results;
  const btScalar d =
      btGjkEpaSolver2::SignedDistance(ToBullet(point), btScalar(0), &shape, transform, results);
  PointContact out;
  if (!(static_cast<double>(d) < 1e30)) return out;  // GJK/EPA failed (SIMD_INFINITY)
  out.gap = static_cast<double>(d);
  out.point_on_shape = ToEigen(results.witnesses[0]);
  const Vec3 delta = point - out.point_on_shape;
  const double len = delta.norm();
  out.normal = len > kTiny ? Vec3((out.gap >= 0.0 ? 1.0 : -1.0) * delta / len)
                           : ToEigen(results.normal).normalized();
  out.valid = true;
  return out;
}

// Point inside a polyhedral shape with face planes (initializePolyhedralFeatures called): the
// signed distance to the margin-expanded surface is max_f (n_f . p + d_f) - margin, attained on
// the face f of the largest plane value (exact for a convex polytope). Returns false for a point
// outside the polytope (GJK answers those: EPA misreports inside points near vertices, see
// docs/narrowphase.md).
bool CalcPolyhedronInsideDistance(const Vec3& p, const btPolyhedralConvexShape& shape,
                                  LocalContact& out) {
  const btConvexPolyhedron* polyhedron = shape.getConvexPolyhedron();
  if (polyhedron == nullptr || polyhedron->m_faces.size() == 0) return false;
  double best = -std::numeric_limits<double>::infinity();
  Vec3 normal = Vec3::Zero();
  for (int f = 0; f < polyhedron->m_faces.size(); ++f) {
    const btScalar* plane = polyhedron->m_faces[f].m_plane;
    const Vec3 n(plane[0], plane[1], plane[2]);
    const double value = n.dot(p) + static_cast<double>(plane[3]);
    if (value > best) {
      best = value;
      normal = n;
    }
  }
  if (best > 0.0) return false;
  const double gap = best - static_cast<double>(shape.getMargin());
  out = {gap, normal, p - gap * normal};
  return true;
}

}  // namespace internal

namespace {

// Stage: the analytic shapes (plane, sphere, capsule, box, cylinder) at local point p; false for
// any other shape type.
bool CalcAnalyticLocalContact(const Vec3& p, const btCollisionShape& shape, LocalContact& out) {
  switch (shape.getShapeType()) {
    case STATIC_PLANE_PROXYTYPE:
      out = CalcPlane(p, static_cast<const btStaticPlaneShape&>(shape));
      return true;
    case SPHERE_SHAPE_PROXYTYPE:
      out = CalcRoundedSegment(p, 2, 0.0, static_cast<const btSphereShape&>(shape).getRadius());
      return true;
    case CAPSULE_SHAPE_PROXYTYPE: {
      const auto& capsule = static_cast<const btCapsuleShape&>(shape);
      out =
          CalcRoundedSegment(p, capsule.getUpAxis(), capsule.getHalfHeight(), capsule.getRadius());
      return true;
    }
    case BOX_SHAPE_PROXYTYPE:
      out = CalcBox(p, ToEigen(static_cast<const btBoxShape&>(shape).getHalfExtentsWithMargin()));
      return true;
    case CYLINDER_SHAPE_PROXYTYPE: {
      const auto& cylinder = static_cast<const btCylinderShape&>(shape);
      const int axis = cylinder.getUpAxis();
      const Vec3 h = ToEigen(cylinder.getHalfExtentsWithMargin());
      out = CalcCylinder(p, axis, h[CylinderRadiusIndex(axis)], h[axis]);
      return true;
    }
    default:
      return false;
  }
}

// Stage: any other convex shape (inside a polyhedron by its face planes, else GJK/EPA) or a
// concave mesh (its closest triangle among those overlapping the box p ± max_distance).
PointContact CalcGeneralShapeContact(const Vec3& point, const Vec3& p,
                                     const btCollisionShape& shape, const btTransform& transform,
                                     double max_distance) {
  LocalContact local;
  if (shape.isPolyhedral() && internal::CalcPolyhedronInsideDistance(
                                  p, static_cast<const btPolyhedralConvexShape&>(shape), local)) {
    return ToWorld(local, transform);
  }
  if (shape.isConvex()) {
    return internal::CalcGjkPointDistance(point, static_cast<const btConvexShape&>(shape),
                                          transform);
  }
  TAUT_DEMAND(shape.isConcave(), "CalcPointShapeDistance: unsupported Bullet shape type ",
              shape.getShapeType(), " (", shape.getName(), ")");
  ClosestTriangleCallback callback(p);
  const btVector3 r(max_distance, max_distance, max_distance);
  static_cast<const btConcaveShape&>(shape).processAllTriangles(&callback, ToBullet(p) - r,
                                                                ToBullet(p) + r);
  if (callback.Result(&local)) return ToWorld(local, transform);
  PointContact none;
  none.gap = std::numeric_limits<double>::infinity();
  return none;
}

}  // namespace

PointContact CalcPointShapeDistance(const Vec3& point, const btCollisionShape& shape,
                                    const btTransform& transform, double max_distance) {
  TAUT_DEMAND(max_distance >= 0.0, "CalcPointShapeDistance: max_distance must be >= 0, got ",
              max_distance);
  PointContact none;
  none.gap = std::numeric_limits<double>::infinity();
  const int type = shape.getShapeType();
  // Planes have an infinite AABB; everything else gets the cheap AABB early out.
  if (type != STATIC_PLANE_PROXYTYPE && CalcAabbDistance(point, shape, transform) > max_distance) {
    return none;
  }
  const Vec3 p = ToEigen(transform.invXform(ToBullet(point)));
  PointContact result = none;
  LocalContact local;
  if (CalcAnalyticLocalContact(p, shape, local)) {
    result = ToWorld(local, transform);
  } else if (type == COMPOUND_SHAPE_PROXYTYPE) {
    // Union: the child with the smallest gap.
    const auto& compound = static_cast<const btCompoundShape&>(shape);
    for (int i = 0; i < compound.getNumChildShapes(); ++i) {
      const PointContact child =
          CalcPointShapeDistance(point, *compound.getChildShape(i),
                                 transform * compound.getChildTransform(i), max_distance);
      if (child.valid && (!result.valid || child.gap < result.gap)) result = child;
    }
  } else {
    result = CalcGeneralShapeContact(point, p, shape, transform, max_distance);
  }
  if (!result.valid || result.gap > max_distance) return none;
  return result;
}

}  // namespace taut
