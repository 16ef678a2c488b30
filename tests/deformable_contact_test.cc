// Contact between deformable bodies (vertex against surface triangle): soft cubes stack without
// passing through each other, and a head-on collision conserves momentum.
#include <gtest/gtest.h>

#include <random>

#include "constraints/deformable_contact_source.h"
#include "constraints/deformable_island_body.h"
#include "demos/scenes/bullet_world_holder.h"
#include "plugin/box_tet_mesher.h"
#include "plugin/tet_element_model.h"

namespace taut {
namespace {

TEST(DeformableContactTest, NearestTrianglePointMatchesADenseSearch) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    const Vec3 a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng)), c(u(rng), u(rng), u(rng));
    const Vec3 p = 2.0 * Vec3(u(rng), u(rng), u(rng));
    const Vec3 beta = internal::CalcNearestTrianglePoint(p, a, b, c);
    ASSERT_NEAR(beta.sum(), 1.0, 1e-12);
    ASSERT_GE(beta.minCoeff(), -1e-12);
    const double found = (p - (beta[0] * a + beta[1] * b + beta[2] * c)).norm();
    double best = HUGE_VAL;
    const int n = 200;
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j) {
        const double s = static_cast<double>(i) / n, t = static_cast<double>(j) / n;
        best = std::min(best, (p - ((1 - s - t) * a + s * b + t * c)).norm());
      }
    EXPECT_LE(found, best + 1e-12) << "trial " << trial;
    EXPECT_GT(found, best - 2e-2) << "trial " << trial;  // the grid's resolution
  }
}

// Deepest penetration of either body's surface points into the other's surface triangles now.
double CalcPenetration(const DeformableBody& a, const DeformableBody& b, const TetMesh& mesh_a,
                       const TetMesh& mesh_b) {
  DeformableBody& ma = const_cast<DeformableBody&>(a);
  DeformableBody& mb = const_cast<DeformableBody&>(b);
  DeformableIslandBody ia(ma), ib(mb);
  const std::vector<IslandBody*> bodies = {&ia, &ib};
  const std::vector<VecX> v = {a.v(), b.v()}, x = {a.x(), b.x()};
  DeformableContactSource source(a, MakeTetContactSurface(mesh_a), b, MakeTetContactSurface(mesh_b),
                                 1, 0.0, 0.05);
  // The normal rows' C is the signed gap of each surface point (penetrating points are always
  // within the activation margin, so they all emit rows).
  std::vector<ConstraintRow> rows;
  source.AppendIslandRows(IslandIterate(0.0, bodies, v, x), rows);
  double penetration = 0.0;
  for (const ConstraintRow& row : rows)
    if (row.friction_of == 0) penetration = std::max(penetration, -row.C);
  return penetration;
}

// Settings of a soft cube.
DeformableBodySettings CubeSettings(const std::string& name, double damping) {
  DeformableBodySettings settings;
  settings.name = name;
  settings.material = {2e5, 0.3, 1000.0};
  settings.mass_damping = damping;
  return settings;
}

// The pair search (points in a spatial hash) finds, for every surface point of either body, the
// same nearest triangle of the other body within the margin as a scan of every triangle: the
// normal rows' gaps agree bit for bit, in the same order, on jittered overlapping cubes.
TEST(DeformableContactTest, PairSearchFindsTheNearestTriangleOfADenseScan) {
  const TetMesh mesh_a = MakeBoxTetMesh(Vec3(0.2, 0.2, 0.2), 4, 4, 4, Vec3(-0.1, -0.1, 0.0));
  const TetMesh mesh_b = MakeBoxTetMesh(Vec3(0.16, 0.16, 0.16), 3, 3, 3, Vec3(-0.05, -0.07, 0.17));
  const DeformableBodySettings settings_a = CubeSettings("a", 0.0);
  const DeformableBodySettings settings_b = CubeSettings("b", 0.0);
  DeformableBody a(std::make_unique<TetElementModel>(std::make_shared<const TetMesh>(mesh_a),
                                                     settings_a.material),
                   settings_a);
  DeformableBody b(std::make_unique<TetElementModel>(std::make_shared<const TetMesh>(mesh_b),
                                                     settings_b.material),
                   settings_b);
  const ContactSurface surface_a = MakeTetContactSurface(mesh_a);
  const ContactSurface surface_b = MakeTetContactSurface(mesh_b);
  const double margin = 0.02;
  DeformableContactSource source(a, surface_a, b, surface_b, 1, 0.0, margin);
  std::mt19937 rng(11);
  std::normal_distribution<double> jitter(0.0, 0.004);
  int total = 0;
  for (int trial = 0; trial < 5; ++trial) {
    std::vector<VecX> x = {a.x(), b.x()};
    for (VecX& xb : x)
      for (int i = 0; i < xb.size(); ++i) xb[i] += jitter(rng);
    DeformableIslandBody ia(a), ib(b);
    const std::vector<IslandBody*> bodies = {&ia, &ib};
    const std::vector<VecX> v = {a.v(), b.v()};
    std::vector<ConstraintRow> rows;
    source.AppendIslandRows(IslandIterate(0.0, bodies, v, x), rows);
    std::vector<double> gaps;
    for (const ConstraintRow& row : rows)
      if (row.friction_of == 0) gaps.push_back(row.C);
    // Dense scan: per point (A's, then B's) the first nearest triangle within the margin.
    std::vector<double> dense;
    const ContactSurface* surfaces[2] = {&surface_a, &surface_b};
    for (int direction = 0; direction < 2; ++direction) {
      const ContactSurface& points = *surfaces[direction];
      const ContactSurface& target = *surfaces[1 - direction];
      const VecX& xp = x[direction];
      const VecX& xt = x[1 - direction];
      for (const ContactPoint& point : points.points) {
        const Vec3 p = CalcContactPointPosition(point, xp);
        double best = margin, gap = 0.0;
        bool found = false;
        for (const Triangle& t : target.triangles) {
          const Vec3 v0 = xt.segment<3>(3 * target.points[t[0]].nodes[0]);
          const Vec3 v1 = xt.segment<3>(3 * target.points[t[1]].nodes[0]);
          const Vec3 v2 = xt.segment<3>(3 * target.points[t[2]].nodes[0]);
          const Vec3 beta = internal::CalcNearestTrianglePoint(p, v0, v1, v2);
          const Vec3 q = beta[0] * v0 + beta[1] * v1 + beta[2] * v2;
          const double distance = (p - q).norm();
          const Vec3 normal = (v1 - v0).cross(v2 - v0);
          if (distance >= best || normal.squaredNorm() == 0.0) continue;
          best = distance;
          gap = normal.normalized().dot(p - q);
          found = true;
        }
        if (found) dense.push_back(gap);
      }
    }
    ASSERT_EQ(gaps.size(), dense.size()) << "trial " << trial;
    for (size_t k = 0; k < gaps.size(); ++k) EXPECT_EQ(gaps[k], dense[k]) << "trial " << trial;
    total += static_cast<int>(gaps.size());
  }
  std::printf("pair search: %d contacts over 5 jittered overlaps, all as the dense scan\n", total);
  EXPECT_GT(total, 50);
}

TEST(DeformableContactTest, SoftCubeDroppedOnAnotherRestsOnItWithoutPassingThrough) {
  BulletWorldHolder holder;
  holder.AddStaticGround(1.0);
  const TetMesh bottom_mesh = MakeBoxTetMesh(Vec3(0.2, 0.2, 0.2), 2, 2, 2, Vec3(-0.1, -0.1, 0.0));
  const TetMesh top_mesh = MakeBoxTetMesh(Vec3(0.16, 0.16, 0.16), 2, 2, 2, Vec3(-0.05, -0.07, 0.3));
  DeformableBody* bottom = holder.world.AddTetBody(bottom_mesh, CubeSettings("bottom", 2.0));
  DeformableBody* top = holder.world.AddTetBody(top_mesh, CubeSettings("top", 2.0));
  double worst = 0.0;
  int contact_rows = 0;
  for (int i = 0; i < 360; ++i) {
    holder.world.stepSimulation(1.0 / 240.0, 1, 1.0 / 240.0);
    worst = std::max(worst, CalcPenetration(*top, *bottom, top_mesh, bottom_mesh));
    contact_rows = std::max(contact_rows, holder.world.last_step_stats().rows_contact);
  }
  double top_low = HUGE_VAL;
  for (int n = 0; n < top->num_nodes(); ++n) top_low = std::min(top_low, top->node_position(n).z());
  std::printf(
      "cube on cube: top cube's lowest node %.4f m, worst overlap %.2e m, islands %d, "
      "contact rows %d\n",
      top_low, worst, holder.world.last_step_stats().islands, contact_rows);
  EXPECT_EQ(holder.world.last_step_stats().islands, 1);  // one island: both cubes
  EXPECT_GT(top_low, 0.17);                              // resting on the bottom cube (~0.2 m)
  EXPECT_LT(worst, 5e-4);                                // never more than 0.5 mm into it
  EXPECT_LT(top->v().cwiseAbs().maxCoeff(), 0.05);       // at rest
}

TEST(DeformableContactTest, HeadOnCollisionOfSoftCubesConservesMomentumAndSeparates) {
  BulletWorldHolder holder;
  holder.world.setGravity(btVector3(0, 0, 0));
  const TetMesh left_mesh = MakeBoxTetMesh(Vec3(0.1, 0.1, 0.1), 2, 2, 2, Vec3(-0.2, -0.05, -0.05));
  const TetMesh right_mesh = MakeBoxTetMesh(Vec3(0.1, 0.1, 0.1), 2, 2, 2, Vec3(0.1, -0.03, -0.04));
  DeformableBody* left = holder.world.AddTetBody(left_mesh, CubeSettings("left", 0.0));
  DeformableBody* right = holder.world.AddTetBody(right_mesh, CubeSettings("right", 0.0));
  VecX v = left->v();
  for (int n = 0; n < left->num_nodes(); ++n) v[3 * n] = 2.0;
  left->set_v(v);
  auto momentum = [&] {
    double p = 0.0;
    for (const DeformableBody* body : {left, right})
      for (int n = 0; n < body->num_nodes(); ++n) p += body->mass()[n] * body->v()[3 * n];
    return p;
  };
  const double p0 = momentum();
  double worst_drift = 0.0, deepest = 0.0;
  for (int i = 0; i < 120; ++i) {
    holder.world.stepSimulation(1.0 / 240.0, 1, 1.0 / 240.0);
    worst_drift = std::max(worst_drift, std::abs(momentum() - p0) / p0);
    deepest = std::max(deepest, CalcPenetration(*left, *right, left_mesh, right_mesh));
  }
  double right_v = 0.0;
  for (int n = 0; n < right->num_nodes(); ++n) right_v += right->mass()[n] * right->v()[3 * n];
  right_v /= right->mass().sum();
  std::printf(
      "head-on at 2 m/s: momentum drift %.2e, deepest overlap %.2e m, right cube now "
      "%.3f m/s\n",
      worst_drift, deepest, right_v);
  EXPECT_LT(worst_drift, 0.01);
  EXPECT_LT(deepest, 1e-4);
  EXPECT_GT(right_v, 0.5);  // the struck cube was pushed away
}

}  // namespace
}  // namespace taut
