// Tests of the point-vs-Bullet-shape narrowphase: gap, sign, normal and closest point per shape,
// the gradient of the gap, GJK/EPA against the analytic shapes, early outs and timings.
#include "bullet_bridge/point_shape_distance.h"

#include <BulletCollision/CollisionShapes/btBoxShape.h>
#include <BulletCollision/CollisionShapes/btBvhTriangleMeshShape.h>
#include <BulletCollision/CollisionShapes/btCapsuleShape.h>
#include <BulletCollision/CollisionShapes/btCompoundShape.h>
#include <BulletCollision/CollisionShapes/btConvexHullShape.h>
#include <BulletCollision/CollisionShapes/btCylinderShape.h>
#include <BulletCollision/CollisionShapes/btSphereShape.h>
#include <BulletCollision/CollisionShapes/btStaticPlaneShape.h>
#include <BulletCollision/CollisionShapes/btTriangleMesh.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>
#include <memory>
#include <random>
#include <vector>

#include "bullet_bridge/eigen_bullet.h"

namespace taut {
namespace {

constexpr double kBig = 10.0;  // max_distance that never cuts off in these tests

// A rotation about a skew axis plus a translation.
btTransform MakeTransform() {
  btTransform t;
  t.setRotation(btQuaternion(btVector3(1, 2, 3).normalized(), btScalar(0.7)));
  t.setOrigin(btVector3(0.3, -0.5, 1.2));
  return t;
}

// Shape-local point -> world.
Vec3 World(const btTransform& t, const Vec3& local) { return ToEigen(t * ToBullet(local)); }
// Shape-local direction -> world.
Vec3 WorldDir(const btTransform& t, const Vec3& local) {
  return ToEigen(t.getBasis() * ToBullet(local));
}

// Checks gap, normal (given in the local frame) and the SDF identity point_on_shape = p − gap n.
void ExpectContact(const btCollisionShape& shape, const btTransform& t, const Vec3& local_point,
                   double gap, const Vec3& local_normal, const char* what) {
  const Vec3 p = World(t, local_point);
  const PointContact c = CalcPointShapeDistance(p, shape, t, kBig);
  ASSERT_TRUE(c.valid) << what;
  EXPECT_NEAR(c.gap, gap, 1e-12) << what;
  EXPECT_LT((c.normal - WorldDir(t, local_normal.normalized())).norm(), 1e-12) << what;
  EXPECT_LT((c.point_on_shape - (p - c.gap * c.normal)).norm(), 1e-12) << what;
}

TEST(PointShapeDistanceTest, PlaneOutsideOnInside) {
  const btStaticPlaneShape plane(btVector3(0, 0, 1), 0.5);
  const btTransform t = MakeTransform();
  for (double g : {0.3, 0.0, -0.2}) ExpectContact(plane, t, {0.2, 0.3, 0.5 + g}, g, {0, 0, 1}, "");
}

TEST(PointShapeDistanceTest, SphereOutsideOnInside) {
  const btSphereShape sphere(0.5);
  const btTransform t = MakeTransform();
  const Vec3 u = Vec3(1, -2, 0.5).normalized();
  ExpectContact(sphere, t, 0.8 * u, 0.3, u, "outside");
  ExpectContact(sphere, t, 0.5 * u, 0.0, u, "on");
  ExpectContact(sphere, t, 0.2 * u, -0.3, u, "inside");
}

TEST(PointShapeDistanceTest, BoxFacesEdgesCornersAndInside) {
  const btBoxShape box(btVector3(0.3, 0.4, 0.5));  // user extents; margin is inside them
  const btTransform t = MakeTransform();
  ExpectContact(box, t, {0.4, 0.1, 0.2}, 0.1, {1, 0, 0}, "face");
  ExpectContact(box, t, {0.4, 0.5, 0.0}, std::sqrt(0.02), {1, 1, 0}, "edge");
  ExpectContact(box, t, {-0.4, 0.5, -0.6}, std::sqrt(0.03), {-1, 1, -1}, "corner");
  ExpectContact(box, t, {0.1, 0.4, 0.0}, 0.0, {0, 1, 0}, "on");
  ExpectContact(box, t, {0.25, 0.0, 0.0}, -0.05, {1, 0, 0}, "inside +x");
  ExpectContact(box, t, {0.0, 0.1, -0.45}, -0.05, {0, 0, -1}, "inside -z");
}

TEST(PointShapeDistanceTest, CapsuleEveryUpAxis) {
  const btTransform t = MakeTransform();
  const btCapsuleShapeX cx(0.2, 0.6);
  const btCapsuleShape cy(0.2, 0.6);
  const btCapsuleShapeZ cz(0.2, 0.6);
  const btCapsuleShape* capsules[] = {&cx, &cy, &cz};
  for (int a = 0; a < 3; ++a) {
    const btCapsuleShape& c = *capsules[a];
    ASSERT_EQ(c.getUpAxis(), a);
    const Vec3 e = Vec3::Unit(a), r = Vec3::Unit((a + 1) % 3);
    ExpectContact(c, t, 0.6 * e, 0.1, e, "end cap");
    ExpectContact(c, t, 0.1 * e + 0.3 * r, 0.1, r, "side");
    ExpectContact(c, t, -0.35 * e + 0.1 * r, std::hypot(0.05, 0.1) - 0.2, Vec3(-0.05 * e + 0.1 * r),
                  "inside end");
    ExpectContact(c, t, 0.15 * r, -0.05, r, "inside side");
  }
}

TEST(PointShapeDistanceTest, CylinderEveryUpAxis) {
  const btTransform t = MakeTransform();
  const double r = 0.3, h = 0.5;
  const btCylinderShapeX cx(btVector3(h, r, r));
  const btCylinderShape cy(btVector3(r, h, r));
  const btCylinderShapeZ cz(btVector3(r, r, h));
  const btCylinderShape* cylinders[] = {&cx, &cy, &cz};
  for (int a = 0; a < 3; ++a) {
    const btCylinderShape& c = *cylinders[a];
    ASSERT_EQ(c.getUpAxis(), a);
    const Vec3 e = Vec3::Unit(a);
    const Vec3 u = (Vec3::Unit((a + 1) % 3) + 2.0 * Vec3::Unit((a + 2) % 3)).normalized();
    ExpectContact(c, t, 0.4 * u + 0.1 * e, 0.1, u, "side");
    ExpectContact(c, t, 0.1 * u - 0.7 * e, 0.2, -e, "cap");
    ExpectContact(c, t, 0.4 * u + 0.6 * e, std::sqrt(0.02), Vec3(u + e), "rim");
    ExpectContact(c, t, 0.3 * u + 0.2 * e, 0.0, u, "on side");
    ExpectContact(c, t, 0.25 * u + 0.1 * e, -0.05, u, "inside near side");
    ExpectContact(c, t, 0.1 * u + 0.45 * e, -0.05, e, "inside near cap");
  }
}

TEST(PointShapeDistanceTest, ConvexHullMeasuresToTheMarginSurface) {
  btConvexHullShape hull;
  for (int i = 0; i < 8; ++i) {
    hull.addPoint(btVector3(i & 1 ? 0.3 : -0.3, i & 2 ? 0.4 : -0.4, i & 4 ? 0.5 : -0.5));
  }
  const double m = hull.getMargin();
  ASSERT_GT(m, 0.0);
  const btTransform t = MakeTransform();
  struct Case {
    Vec3 local;
    double gap;
    Vec3 normal;
  };
  const Case cases[] = {{{0.5, 0.1, 0.2}, 0.2 - m, {1, 0, 0}},
                        {{0.0, 0.1, -0.7}, 0.2 - m, {0, 0, -1}},
                        {{0.25, 0.0, 0.0}, -0.05 - m, {1, 0, 0}},
                        {{0.0, -0.3, 0.1}, -0.1 - m, {0, -1, 0}}};
  for (const Case& k : cases) {
    const Vec3 p = World(t, k.local);
    const PointContact c = CalcPointShapeDistance(p, hull, t, kBig);
    ASSERT_TRUE(c.valid);
    EXPECT_NEAR(c.gap, k.gap, 1e-6) << k.local.transpose();
    EXPECT_LT((c.normal - WorldDir(t, k.normal)).norm(), 1e-6) << k.local.transpose();
    EXPECT_LT((c.point_on_shape - (p - c.gap * c.normal)).norm(), 1e-6);
  }
}

TEST(PointShapeDistanceTest, CompoundPicksTheNearerChild) {
  btSphereShape a(0.2), b(0.3);
  btCompoundShape compound;
  btTransform ta = btTransform::getIdentity(), tb = btTransform::getIdentity();
  ta.setOrigin(btVector3(-1, 0, 0));
  tb.setOrigin(btVector3(1, 0, 0));
  compound.addChildShape(ta, &a);
  compound.addChildShape(tb, &b);
  const btTransform t = MakeTransform();
  ExpectContact(compound, t, {-0.5, 0, 0}, 0.3, {1, 0, 0}, "near a");
  ExpectContact(compound, t, {0.4, 0, 0}, 0.3, {-1, 0, 0}, "near b");
  ExpectContact(compound, t, {1.1, 0, 0}, -0.2, {1, 0, 0}, "inside b");
  ExpectContact(compound, t, {-1, 0.5, 0}, 0.3, {0, 1, 0}, "above a");
}

// Two triangles covering [-1,1]² at z = 0, wound counter-clockwise seen from +z.
struct GroundQuad {
  GroundQuad() : shape(MakeMesh(&mesh), true) {}
  static btTriangleMesh* MakeMesh(btTriangleMesh* m) {
    m->addTriangle(btVector3(-1, -1, 0), btVector3(1, -1, 0), btVector3(1, 1, 0));
    m->addTriangle(btVector3(-1, -1, 0), btVector3(1, 1, 0), btVector3(-1, 1, 0));
    return m;
  }
  btTriangleMesh mesh;
  btBvhTriangleMeshShape shape;
};

TEST(PointShapeDistanceTest, TriangleMeshQuadGivesThePlaneDistance) {
  GroundQuad quad;
  const btTransform t = MakeTransform();
  for (double z : {0.3, 0.0, -0.1}) {
    for (const Vec3& xy : {Vec3(0.5, -0.2, 0), Vec3(-0.7, 0.6, 0), Vec3(0.2, 0.2, 0)}) {
      ExpectContact(quad.shape, t, xy + Vec3(0, 0, z), z, {0, 0, 1}, "over the quad");
    }
  }
  // Beyond the edge x = 1 the closest point is on the edge.
  ExpectContact(quad.shape, t, {1.3, 0.0, 0.4}, 0.5, {0.3, 0, 0.4}, "past the edge");
  // One-sided: deeper than max_distance behind the mesh nothing is found.
  const PointContact deep = CalcPointShapeDistance(World(t, {0, 0, -0.5}), quad.shape, t, 0.3);
  EXPECT_FALSE(deep.valid);
}

TEST(PointShapeDistanceTest, ClosestPointOnTriangleMatchesBruteForce) {
  const Vec3 a(0, 0, 0), b(1, 0.2, 0.1), c(0.3, 0.9, -0.2);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 2.0);
  for (int i = 0; i < 200; ++i) {
    const Vec3 p(u(rng), u(rng), u(rng));
    const double d = (p - internal::CalcClosestPointOnTriangle(p, a, b, c)).norm();
    double best = 1e9;
    for (int s = 0; s <= 200; ++s) {
      for (int k = 0; k <= 200 - s; ++k) {
        const Vec3 q = a + s / 200.0 * (b - a) + k / 200.0 * (c - a);
        best = std::min(best, (p - q).norm());
      }
    }
    EXPECT_LE(d, best + 1e-12);
    EXPECT_GT(d, best - 1e-2);
  }
}

// Shapes for the property tests, with a sampling box half-size in the local frame.
struct NamedShape {
  const char* name;
  const btCollisionShape* shape;
  double extent;
};

// The gradient of the gap is the normal (central differences; the SDF has |∇gap| = 1), and the
// gap is 1-Lipschitz and continuous along lines through the surface.
TEST(PointShapeDistanceTest, GapGradientIsTheNormalAndGapIsContinuous) {
  const btStaticPlaneShape plane(btVector3(0, 0, 1), 0.1);
  const btSphereShape sphere(0.5);
  const btBoxShape box(btVector3(0.3, 0.4, 0.5));
  const btCapsuleShapeX capsule(0.2, 0.6);
  const btCylinderShapeZ cylinder(btVector3(0.3, 0.3, 0.5));
  btConvexHullShape hull;  // an octahedron, GJK/EPA path
  for (int k = 0; k < 6; ++k) hull.addPoint(ToBullet((k < 3 ? 0.5 : -0.5) * Vec3::Unit(k % 3)));
  GroundQuad quad;
  const NamedShape shapes[] = {{"plane", &plane, 0.6},       {"sphere", &sphere, 0.8},
                               {"box", &box, 0.7},           {"capsule", &capsule, 0.8},
                               {"cylinder", &cylinder, 0.7}, {"hull", &hull, 0.8},
                               {"mesh", &quad.shape, 0.6}};
  const btTransform t = MakeTransform();
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (const NamedShape& s : shapes) {
    for (int i = 0; i < 300; ++i) {
      const Vec3 p = World(t, s.extent * Vec3(u(rng), u(rng), u(rng)));
      const PointContact c = CalcPointShapeDistance(p, *s.shape, t, kBig);
      ASSERT_TRUE(c.valid) << s.name;
      ASSERT_NEAR(c.normal.norm(), 1.0, 1e-12) << s.name;
      Vec3 grad;
      const double step = 1e-6;
      for (int k = 0; k < 3; ++k) {
        const Vec3 dp = step * Vec3::Unit(k);
        grad[k] = (CalcPointShapeDistance(p + dp, *s.shape, t, kBig).gap -
                   CalcPointShapeDistance(p - dp, *s.shape, t, kBig).gap) /
                  (2 * step);
      }
      EXPECT_GT(grad.norm(), 0.5) << s.name;
      EXPECT_LT((grad - c.normal).norm(), 1e-5) << s.name << " at " << p.transpose();
    }
    // March from outside to the center: steps change the gap by at most the step length, and
    // the sign changes once.
    const Vec3 dir = WorldDir(t, Vec3(0.3, -0.2, 1.0).normalized());
    const Vec3 center = World(t, Vec3(0.05, 0.02, 0.0));
    const double step = 1e-3;
    double prev = CalcPointShapeDistance(center + 0.9 * dir, *s.shape, t, kBig).gap;
    int sign_changes = 0;
    for (double a = 0.9 - step; a > -0.1; a -= step) {
      const double g = CalcPointShapeDistance(center + a * dir, *s.shape, t, kBig).gap;
      EXPECT_LE(std::abs(g - prev), step * (1 + 1e-9)) << s.name << " a=" << a;
      sign_changes += (g < 0) != (prev < 0);
      prev = g;
    }
    EXPECT_EQ(sign_changes, 1) << s.name;
  }
}

// Max |gap difference| and max normal difference between GJK/EPA and the analytic result.
struct Agreement {
  double gap_outside = 0, gap_inside = 0, normal_outside = 0, normal_inside = 0;
};

// Compares the two methods on random points of [-extent, extent]³ (local frame).
Agreement CompareWithGjk(const btConvexShape& shape, double extent) {
  const btTransform t = MakeTransform();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-extent, extent);
  Agreement out;
  for (int i = 0; i < 2000; ++i) {
    const Vec3 p = World(t, Vec3(u(rng), u(rng), u(rng)));
    const PointContact a = CalcPointShapeDistance(p, shape, t, kBig);
    const PointContact g = internal::CalcGjkPointDistance(p, shape, t);
    EXPECT_TRUE(a.valid && g.valid);
    const double dg = std::abs(a.gap - g.gap), dn = (a.normal - g.normal).norm();
    double& gap_max = a.gap >= 0 ? out.gap_outside : out.gap_inside;
    double& normal_max = a.gap >= 0 ? out.normal_outside : out.normal_inside;
    gap_max = std::max(gap_max, dg);
    normal_max = std::max(normal_max, dn);
  }
  std::printf("  %-22s gap diff out %.2e in %.2e | normal diff out %.2e in %.2e\n", shape.getName(),
              out.gap_outside, out.gap_inside, out.normal_outside, out.normal_inside);
  return out;
}

TEST(PointShapeDistanceTest, GjkEpaAgreesWithAnalyticShapes) {
  const btSphereShape sphere(0.5);
  const btCapsuleShapeZ capsule(0.2, 0.6);
  btBoxShape sharp_box(btVector3(0.3, 0.4, 0.5));
  sharp_box.setMargin(0.0);                        // keeps the user extents, removes the rounding
  const btBoxShape box(btVector3(0.3, 0.4, 0.5));  // default margin 0.04: rounded edges for GJK
  const Agreement s = CompareWithGjk(sphere, 0.8);
  const Agreement c = CompareWithGjk(capsule, 0.8);
  const Agreement b0 = CompareWithGjk(sharp_box, 0.7);
  const Agreement b = CompareWithGjk(box, 0.7);
  for (const Agreement& a : {s, c, b0}) {
    EXPECT_LT(a.gap_outside, 1e-6);
    EXPECT_LT(a.gap_inside, 1e-4);
  }
  // Rounded edges of radius m: the surfaces differ by up to (√3 − 1) m at a corner.
  const double m = box.getMargin();
  EXPECT_LT(b.gap_outside, (std::sqrt(3.0) - 1.0) * m + 1e-6);
  EXPECT_GT(b.gap_outside, 0.1 * m);  // the difference is real
}

TEST(PointShapeDistanceTest, MaxDistanceEarlyOutAndBadInput) {
  const btSphereShape sphere(0.5);
  const btBoxShape box(btVector3(0.3, 0.4, 0.5));
  const btStaticPlaneShape plane(btVector3(0, 0, 1), 0.0);
  const btTransform t = MakeTransform();
  const Vec3 p = World(t, {1.5, 0, 0});  // gap 1.0 to the sphere
  EXPECT_FALSE(CalcPointShapeDistance(p, sphere, t, 0.9).valid);
  EXPECT_TRUE(CalcPointShapeDistance(p, sphere, t, 1.1).valid);
  EXPECT_FALSE(CalcPointShapeDistance(World(t, {5, 5, 5}), box, t, 1.0).valid);
  EXPECT_FALSE(CalcPointShapeDistance(World(t, {0, 0, 2}), plane, t, 1.0).valid);
  EXPECT_TRUE(CalcPointShapeDistance(World(t, {0, 0, -2}), plane, t, 1.0).valid);
  EXPECT_THROW(CalcPointShapeDistance(p, sphere, t, -1.0), InputError);
}

TEST(PointShapeDistanceTest, TimingPerShape) {
  btConvexHullShape hull;
  for (int i = 0; i < 8; ++i) {
    hull.addPoint(btVector3(i & 1 ? 0.3 : -0.3, i & 2 ? 0.4 : -0.4, i & 4 ? 0.5 : -0.5));
  }
  const btStaticPlaneShape plane(btVector3(0, 0, 1), 0.0);
  const btSphereShape sphere(0.5);
  const btBoxShape box(btVector3(0.3, 0.4, 0.5));
  const btCapsuleShapeZ capsule(0.2, 0.6);
  const btCylinderShapeZ cylinder(btVector3(0.3, 0.3, 0.5));
  GroundQuad quad;
  const NamedShape shapes[] = {{"plane", &plane, 0.6},
                               {"sphere", &sphere, 0.8},
                               {"box", &box, 0.7},
                               {"capsule", &capsule, 0.8},
                               {"cylinder", &cylinder, 0.7},
                               {"hull (GJK/EPA)", &hull, 0.7},
                               {"mesh (2 tris)", &quad.shape, 0.6}};
  const btTransform t = MakeTransform();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (const NamedShape& s : shapes) {
    std::vector<Vec3> points;
    for (int i = 0; i < 256; ++i)
      points.push_back(World(t, s.extent * Vec3(u(rng), u(rng), u(rng))));
    std::vector<double> per_call;
    double sink = 0.0;
    for (int rep = 0; rep < 21; ++rep) {
      const auto start = std::chrono::steady_clock::now();
      for (const Vec3& p : points) sink += CalcPointShapeDistance(p, *s.shape, t, kBig).gap;
      const std::chrono::duration<double, std::nano> ns = std::chrono::steady_clock::now() - start;
      per_call.push_back(ns.count() / points.size());
    }
    std::nth_element(per_call.begin(), per_call.begin() + 10, per_call.end());
    std::printf("  %-16s median %8.1f ns/call\n", s.name, per_call[10]);
    EXPECT_TRUE(std::isfinite(sink));
    EXPECT_GT(per_call[10], 0.0);
  }
}

}  // namespace
}  // namespace taut

namespace taut {
namespace {

// With face planes (initializePolyhedralFeatures), inside points of a hull are measured exactly
// against the planes, including the near-vertex points where EPA misreports the sign
// (docs/narrowphase.md): octahedron |x| + |y| + |z| <= 0.5, depth (|x|+|y|+|z| - 0.5)/sqrt(3).
TEST(PointShapeDistanceTest, HullInsidePointsUseFacePlanesWhenAvailable) {
  btConvexHullShape hull;
  for (int k = 0; k < 6; ++k) hull.addPoint(ToBullet((k < 3 ? 0.5 : -0.5) * Vec3::Unit(k % 3)));
  hull.initializePolyhedralFeatures();
  const double margin = hull.getMargin();
  btTransform t(btQuaternion(btVector3(1, 2, 3).normalized(), 0.7), btVector3(0.3, -0.2, 1.0));
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  int tested = 0;
  for (int i = 0; i < 10000 && tested < 500; ++i) {
    const Vec3 local(u(rng), u(rng), u(rng));
    const double l1 = local.cwiseAbs().sum();
    if (l1 >= 0.5) continue;
    ++tested;
    const Vec3 world = ToEigen(t * ToBullet(local));
    const PointContact c = CalcPointShapeDistance(world, hull, t, 1.0);
    ASSERT_TRUE(c.valid);
    EXPECT_NEAR(c.gap, (l1 - 0.5) / std::sqrt(3.0) - margin, 1e-12)
        << "point " << local.transpose();
    const Vec3 expected_normal =
        ToEigen(t.getBasis() * ToBullet(Vec3(local.array().sign()) / std::sqrt(3.0)));
    if ((local.cwiseAbs().array() > 1e-9).all())
      EXPECT_GT(c.normal.dot(expected_normal), 1.0 - 1e-9);
  }
  EXPECT_EQ(tested, 500);
}

}  // namespace
}  // namespace taut
