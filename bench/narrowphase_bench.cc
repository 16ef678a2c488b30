// Point-vs-shape signed distance, the query behind taut's contact rows (gap, sign, unit normal,
// also for points inside the shape), for a sphere, box, capsule, cylinder and convex hull, by
//  - taut_analytic: CalcPointShapeDistance (analytic for the four primitives, Bullet GJK/EPA for
//    the hull), what DeformableWorld calls;
//  - bullet_gjk_epa: btGjkEpaSolver2::SignedDistance for every shape
//  (internal::CalcGjkPointDistance);
//  - fcl_libccd / fcl_indep: fcl::distance with enable_signed_distance, the point as a sphere of
//    radius 0, libccd-based or FCL's own GJK solver;
//  - libccd_gjk_epa / libccd_mpr: ccdGJKPenetration / ccdMPRPenetration with a point support
//    function (libccd has no distance query: outside points only get "not intersecting");
//  - hull_planes_then_gjk (hull only): face planes for inside points, Bullet GJK outside, a
//    candidate fix for the hull sign errors of GJK/EPA measured here.
// The shapes are posed by one rotation + translation; 1,024 points (512 inside, 512 outside,
// none within 1e-3 m of the surface) are drawn around each. Time per query is the counter
// s_per_query; accuracy against the closed-form answer is in gap_err_max [m] (over queries that
// return a gap), sign_errors, normal_errors (angle > 0.01 rad), no_answer (no gap returned or
// failure). Bullet shapes have margin 0 so that every method measures the same sharp surface.
#include <BulletCollision/CollisionShapes/btConvexHullShape.h>
#include <BulletCollision/CollisionShapes/btConvexPolyhedron.h>
#include <benchmark/benchmark.h>
#include <btBulletCollisionCommon.h>
#include <ccd/ccd.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/geometry/shape/convex.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/narrowphase/distance.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "bullet_bridge/point_shape_distance.h"

namespace taut {
namespace {

enum class Shape { kSphere, kBox, kCapsule, kCylinder, kHull };
const char* const kShapeNames[] = {"sphere", "box", "capsule", "cylinder", "hull"};

// One answer of a method: gap [m] (< 0 inside) and outward unit normal; has_gap = false when the
// method only tells "separated" (libccd) or fails; inside is the method's sign claim.
struct Answer {
  bool has_gap = false;
  bool inside = false;
  double gap = 0.0;
  Vec3 normal = Vec3::Zero();
};

constexpr double kRadius = 0.3, kHalf = 0.4;  // sphere, capsule, cylinder radius; half length
const Vec3 kBoxHalf(0.5, 0.3, 0.2);           // box half extents
const Vec3 kHullScale(0.5, 0.35, 0.25);       // icosahedron stretched per axis

// Regular icosahedron (circumradius 1) scaled by kHullScale: vertices and outward triangles.
void MakeHull(std::vector<Vec3>& vertices, std::vector<std::array<int, 3>>& triangles) {
  const double phi = (1.0 + std::sqrt(5.0)) / 2.0, s = 1.0 / std::sqrt(1.0 + phi * phi);
  for (int a : {-1, 1})
    for (int b : {-1, 1}) {
      vertices.emplace_back(0, a, b * phi);
      vertices.emplace_back(a, b * phi, 0);
      vertices.emplace_back(b * phi, 0, a);
    }
  // Faces: vertex triples at mutual distance 2 (the edge length before scaling).
  const int n = static_cast<int>(vertices.size());
  auto edge = [&](int i, int j) { return std::abs((vertices[i] - vertices[j]).norm() - 2) < 1e-9; };
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j)
      for (int k = j + 1; k < n; ++k)
        if (edge(i, j) && edge(j, k) && edge(i, k)) {
          const Vec3 normal = (vertices[j] - vertices[i]).cross(vertices[k] - vertices[i]);
          triangles.push_back(normal.dot(vertices[i]) > 0 ? std::array<int, 3>{i, j, k}
                                                          : std::array<int, 3>{i, k, j});
        }
  for (Vec3& v : vertices) v = (s * v).cwiseProduct(kHullScale);
}

// Closed-form signed distance in the shape's frame: gap and outward normal.
Answer CalcReference(Shape shape, const Vec3& p, const std::vector<Vec3>& hull,
                     const std::vector<std::array<int, 3>>& faces) {
  Answer a;
  a.has_gap = true;
  // Signed distance to the 2D box |x| <= hx, |z| <= hz in (radial, axial) coordinates.
  auto box2 = [&](double x, double z, double hx, double hz, const Vec3& ex, const Vec3& ez) {
    const double qx = x - hx, qz = std::abs(z) - hz, sz = z >= 0 ? 1.0 : -1.0;
    if (qx > 0 || qz > 0) {
      const double dx = std::max(qx, 0.0), dz = std::max(qz, 0.0), d = std::hypot(dx, dz);
      a.gap = d, a.normal = (dx * ex + dz * sz * ez) / d;
    } else if (qx > qz) {
      a.gap = qx, a.normal = ex;
    } else {
      a.gap = qz, a.normal = sz * ez;
    }
  };
  const Vec3 ez = Vec3::UnitZ();
  const Vec3 radial(p.x(), p.y(), 0.0);
  switch (shape) {
    case Shape::kSphere:
      a.gap = p.norm() - kRadius, a.normal = p.normalized();
      break;
    case Shape::kCapsule: {
      const Vec3 d = p - std::clamp(p.z(), -kHalf, kHalf) * ez;
      a.gap = d.norm() - kRadius, a.normal = d.normalized();
      break;
    }
    case Shape::kCylinder:
      box2(radial.norm(), p.z(), kRadius, kHalf, radial.normalized(), ez);
      break;
    case Shape::kBox: {
      // Outside: distance to the clamped point; inside: the nearest face.
      const Vec3 q = p.cwiseMax(-kBoxHalf).cwiseMin(kBoxHalf);
      if ((p - q).norm() > 0) {
        a.gap = (p - q).norm(), a.normal = (p - q).normalized();
      } else {
        int k = 0;
        a.gap = (p.cwiseAbs() - kBoxHalf).maxCoeff(&k);
        a.normal = (p[k] >= 0 ? 1.0 : -1.0) * Vec3::Unit(k);
      }
      break;
    }
    case Shape::kHull: {
      // Inside: the largest face-plane value; outside: the nearest triangle.
      double best_plane = -HUGE_VAL, best_dist = HUGE_VAL;
      Vec3 plane_normal, closest;
      for (const auto& f : faces) {
        const Vec3 n = (hull[f[1]] - hull[f[0]]).cross(hull[f[2]] - hull[f[0]]).normalized();
        const double h = n.dot(p - hull[f[0]]);
        if (h > best_plane) best_plane = h, plane_normal = n;
        const Vec3 c = internal::CalcClosestPointOnTriangle(p, hull[f[0]], hull[f[1]], hull[f[2]]);
        if ((p - c).norm() < best_dist) best_dist = (p - c).norm(), closest = c;
      }
      if (best_plane <= 0) {
        a.gap = best_plane, a.normal = plane_normal;
      } else {
        a.gap = best_dist, a.normal = (p - closest) / best_dist;
      }
      break;
    }
  }
  a.inside = a.gap < 0;
  return a;
}

// A posed shape in every library's form, with its query points and their reference answers.
struct Fixture {
  Shape shape;
  Eigen::Isometry3d pose;  // world from shape
  std::vector<Vec3> hull;
  std::vector<std::array<int, 3>> faces;
  std::unique_ptr<btConvexShape> bullet;
  btTransform bullet_pose;
  std::shared_ptr<fcl::CollisionGeometryd> fcl_shape;
  std::vector<Vec3> points;      // world
  std::vector<Answer> expected;  // world normals

  explicit Fixture(Shape s);
  // A direction in the shape's frame expressed in world.
  Vec3 ToWorld(const Vec3& n) const { return pose.linear() * n; }
};

Fixture::Fixture(Shape s) : shape(s) {
  pose = Eigen::Translation3d(0.3, -0.2, 0.5) *
         Eigen::AngleAxisd(0.7, Vec3(0.3, -0.5, 0.8).normalized());
  MakeHull(hull, faces);
  switch (shape) {
    case Shape::kSphere:
      bullet = std::make_unique<btSphereShape>(kRadius);
      fcl_shape = std::make_shared<fcl::Sphered>(kRadius);
      break;
    case Shape::kBox:
      bullet = std::make_unique<btBoxShape>(btVector3(kBoxHalf.x(), kBoxHalf.y(), kBoxHalf.z()));
      fcl_shape = std::make_shared<fcl::Boxd>(2.0 * kBoxHalf);
      break;
    case Shape::kCapsule:
      bullet = std::make_unique<btCapsuleShapeZ>(kRadius, 2.0 * kHalf);
      fcl_shape = std::make_shared<fcl::Capsuled>(kRadius, 2.0 * kHalf);
      break;
    case Shape::kCylinder:
      bullet = std::make_unique<btCylinderShapeZ>(btVector3(kRadius, kRadius, kHalf));
      fcl_shape = std::make_shared<fcl::Cylinderd>(kRadius, 2.0 * kHalf);
      break;
    case Shape::kHull: {
      auto hull_shape = std::make_unique<btConvexHullShape>();
      for (const Vec3& v : hull) hull_shape->addPoint(btVector3(v.x(), v.y(), v.z()), false);
      hull_shape->recalcLocalAabb();
      hull_shape->initializePolyhedralFeatures();
      bullet = std::move(hull_shape);
      auto vertices = std::make_shared<std::vector<Vec3>>(hull);
      auto polygons = std::make_shared<std::vector<int>>();
      for (const auto& f : faces) polygons->insert(polygons->end(), {3, f[0], f[1], f[2]});
      fcl_shape =
          std::make_shared<fcl::Convexd>(vertices, static_cast<int>(faces.size()), polygons);
      break;
    }
  }
  // Sphere and capsule keep their radius as margin; the others measure the sharp surface.
  if (shape != Shape::kSphere && shape != Shape::kCapsule) bullet->setMargin(0.0);
  const Eigen::Quaterniond q(pose.linear());
  bullet_pose = btTransform(
      btQuaternion(q.x(), q.y(), q.z(), q.w()),
      btVector3(pose.translation().x(), pose.translation().y(), pose.translation().z()));
  // 512 points inside and 512 outside, uniform in the local bounds grown by 0.25 m.
  btVector3 lo, hi;
  bullet->getAabb(btTransform::getIdentity(), lo, hi);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int inside = 0, outside = 0;
  while (inside < 512 || outside < 512) {
    Vec3 p;
    for (int i = 0; i < 3; ++i) p[i] = lo[i] - 0.25 + (hi[i] - lo[i] + 0.5) * u(random);
    Answer a = CalcReference(shape, p, hull, faces);
    if (std::abs(a.gap) < 1e-3 || (a.inside ? inside : outside) >= 512) continue;
    ++(a.inside ? inside : outside);
    a.normal = ToWorld(a.normal);
    points.push_back(pose * p);
    expected.push_back(a);
  }
}

// The answer from a taut PointContact.
Answer FromPointContact(const PointContact& c) {
  Answer a;
  if (!c.valid) return a;
  a.has_gap = true, a.gap = c.gap, a.inside = c.gap < 0, a.normal = c.normal;
  return a;
}

// fcl::distance of the shape and a radius-0 sphere at p; normal from the nearest points.
Answer CalcFcl(const Fixture& f, const Vec3& p, fcl::GJKSolverType solver) {
  static const fcl::Sphered point(0.0);
  const fcl::DistanceRequestd request(true, true, 0.0, 0.0, 1e-6, solver);
  fcl::DistanceResultd result;
  Answer a;
  try {
    fcl::distance(f.fcl_shape.get(), fcl::Transform3d(f.pose.matrix()), &point,
                  fcl::Transform3d(Eigen::Translation3d(p)), request, result);
  } catch (const std::exception&) {
    return a;  // FCL throws on some failed configurations
  }
  if (!std::isfinite(result.min_distance)) return a;
  a.has_gap = true, a.gap = result.min_distance, a.inside = a.gap < 0;
  const Vec3 d = p - result.nearest_points[0];
  if (d.norm() > 1e-12) a.normal = (a.inside ? -1.0 : 1.0) * d.normalized();
  return a;
}

// libccd object: a posed Fixture or a point.
struct CcdObject {
  const Fixture* fixture;  // null: the point
  Vec3 point;
};

// Support point of the shape in its frame for direction d (sharp surfaces, margin 0).
Vec3 CalcLocalSupport(const Fixture& f, const Vec3& d) {
  auto sign = [](double x) { return x >= 0 ? 1.0 : -1.0; };
  const Vec3 radial(d.x(), d.y(), 0.0);
  const Vec3 radial_unit = radial.norm() > 1e-300 ? Vec3(radial.normalized()) : Vec3::UnitX();
  switch (f.shape) {
    case Shape::kSphere:
      return kRadius * d.normalized();
    case Shape::kBox:
      return Vec3(sign(d.x()), sign(d.y()), sign(d.z())).cwiseProduct(kBoxHalf);
    case Shape::kCapsule:
      return sign(d.z()) * kHalf * Vec3::UnitZ() + kRadius * d.normalized();
    case Shape::kCylinder:
      return kRadius * radial_unit + sign(d.z()) * kHalf * Vec3::UnitZ();
    case Shape::kHull: {
      int best = 0;
      for (size_t i = 1; i < f.hull.size(); ++i)
        if (f.hull[i].dot(d) > f.hull[best].dot(d)) best = static_cast<int>(i);
      return f.hull[best];
    }
  }
  return Vec3::Zero();
}

// libccd callbacks: support point and centre in world.
void CcdSupport(const void* obj, const ccd_vec3_t* dir, ccd_vec3_t* out) {
  const auto& o = *static_cast<const CcdObject*>(obj);
  Vec3 s = o.point;
  if (o.fixture != nullptr) {
    const Vec3 d(dir->v[0], dir->v[1], dir->v[2]);
    s = o.fixture->pose * CalcLocalSupport(*o.fixture, o.fixture->pose.linear().transpose() * d);
  }
  for (int i = 0; i < 3; ++i) out->v[i] = s[i];
}
void CcdCenter(const void* obj, ccd_vec3_t* out) {
  const auto& o = *static_cast<const CcdObject*>(obj);
  const Vec3 c = o.fixture != nullptr ? Vec3(o.fixture->pose.translation()) : o.point;
  for (int i = 0; i < 3; ++i) out->v[i] = c[i];
}

// Penetration of the point into the shape by libccd (GJK+EPA or MPR); outside: no gap.
Answer CalcLibccd(const Fixture& f, const Vec3& p, bool mpr) {
  ccd_t ccd;
  CCD_INIT(&ccd);
  ccd.support1 = ccd.support2 = CcdSupport;
  ccd.center1 = ccd.center2 = CcdCenter;
  ccd.max_iterations = 100;
  ccd.epa_tolerance = ccd.mpr_tolerance = 1e-9;
  const CcdObject shape{&f, Vec3::Zero()}, point{nullptr, p};
  ccd_real_t depth = 0;
  ccd_vec3_t dir, pos;
  const int hit = mpr ? ccdMPRPenetration(&shape, &point, &ccd, &depth, &dir, &pos)
                      : ccdGJKPenetration(&shape, &point, &ccd, &depth, &dir, &pos);
  Answer a;
  a.inside = hit == 0;
  if (hit != 0) return a;
  // Moving the point by depth along dir separates it: dir is the outward normal.
  a.has_gap = true, a.gap = -depth, a.normal = Vec3(dir.v[0], dir.v[1], dir.v[2]).normalized();
  return a;
}

// Hull only: the sign and the inside depth from the face planes of Bullet's polyhedral features
// (gap = max_f n_f·p + d_f, exact for a convex polytope), Bullet GJK only for outside points.
Answer CalcHullPlanesThenGjk(const Fixture& f, const Vec3& p) {
  const auto& hull = static_cast<const btPolyhedralConvexShape&>(*f.bullet);
  const btConvexPolyhedron& polyhedron = *hull.getConvexPolyhedron();
  const btVector3 q = f.bullet_pose.invXform(btVector3(p.x(), p.y(), p.z()));
  double best = -HUGE_VAL;
  Vec3 normal = Vec3::Zero();
  for (int i = 0; i < polyhedron.m_faces.size(); ++i) {
    const btScalar* plane = polyhedron.m_faces[i].m_plane;
    const double h = plane[0] * q.x() + plane[1] * q.y() + plane[2] * q.z() + plane[3];
    if (h > best) best = h, normal = Vec3(plane[0], plane[1], plane[2]);
  }
  if (best > 0)
    return FromPointContact(internal::CalcGjkPointDistance(p, *f.bullet, f.bullet_pose));
  Answer a;
  a.has_gap = true, a.inside = true, a.gap = best - hull.getMargin();
  a.normal = f.ToWorld(normal);
  return a;
}

using Method = std::function<Answer(const Fixture&, const Vec3&)>;

// Times the method over the fixture's points, then scores every answer against the reference.
void RunMethod(benchmark::State& state, Shape shape, const Method& method) {
  const Fixture fixture(shape);
  const int n = static_cast<int>(fixture.points.size());
  for (auto _ : state)
    for (const Vec3& p : fixture.points) benchmark::DoNotOptimize(method(fixture, p));
  double gap_err = 0.0;
  int sign_errors = 0, normal_errors = 0, no_answer = 0;
  for (int i = 0; i < n; ++i) {
    const Answer a = method(fixture, fixture.points[i]);
    const Answer& e = fixture.expected[i];
    // A method with no gap still claims a side (libccd: intersecting or not).
    if (a.inside != e.inside) ++sign_errors;
    if (!a.has_gap) {
      ++no_answer;
      continue;
    }
    gap_err = std::max(gap_err, std::abs(a.gap - e.gap));
    const double cosine = a.normal.dot(e.normal);
    if (!(cosine > std::cos(0.01))) ++normal_errors;
  }
  state.counters["s_per_query"] =
      benchmark::Counter(static_cast<double>(n) * state.iterations(),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["gap_err_max"] = gap_err;
  state.counters["sign_errors"] = sign_errors;
  state.counters["normal_errors"] = normal_errors;
  state.counters["no_answer"] = no_answer;
  state.counters["queries"] = n;
}

// Registers BM_PointDistance/<method>/<shape> for every method and shape.
const bool kRegistered = [] {
  const std::vector<std::pair<std::string, Method>> methods = {
      {"taut_analytic",
       [](const Fixture& f, const Vec3& p) {
         return FromPointContact(CalcPointShapeDistance(p, *f.bullet, f.bullet_pose, 10.0));
       }},
      {"bullet_gjk_epa",
       [](const Fixture& f, const Vec3& p) {
         return FromPointContact(internal::CalcGjkPointDistance(p, *f.bullet, f.bullet_pose));
       }},
      {"fcl_libccd",
       [](const Fixture& f, const Vec3& p) { return CalcFcl(f, p, fcl::GST_LIBCCD); }},
      {"fcl_indep", [](const Fixture& f, const Vec3& p) { return CalcFcl(f, p, fcl::GST_INDEP); }},
      {"libccd_gjk_epa", [](const Fixture& f, const Vec3& p) { return CalcLibccd(f, p, false); }},
      {"libccd_mpr", [](const Fixture& f, const Vec3& p) { return CalcLibccd(f, p, true); }},
      {"hull_planes_then_gjk", CalcHullPlanesThenGjk},
  };
  for (const auto& [name, method] : methods)
    for (int s = 0; s < 5; ++s) {
      if (name == "hull_planes_then_gjk" && static_cast<Shape>(s) != Shape::kHull) continue;
      const Method m = method;
      // FCL 0.7 (Debian's build keeps asserts) aborts in distance-inl.h:177 for GST_INDEP with a
      // point inside a Convex: no contact of its collide() fallback has a positive depth
      // (assert(index != -1)). Reported, not run.
      const bool aborts = name == "fcl_indep" && static_cast<Shape>(s) == Shape::kHull;
      benchmark::RegisterBenchmark(
          ("BM_PointDistance/" + name + "/" + kShapeNames[s]).c_str(),
          [m, s, aborts](benchmark::State& state) {
            if (aborts) {
              state.SkipWithError("FCL 0.7 GST_INDEP aborts for a point inside a Convex");
              for (auto _ : state) {
              }
              return;
            }
            RunMethod(state, static_cast<Shape>(s), m);
          })
          ->Unit(benchmark::kMicrosecond);
    }
  return true;
}();

}  // namespace
}  // namespace taut
