// Self-contact of one deformable body (docs/math.md §5.5, self-contact): a soft hairpin beam whose
// upper arm sags onto its lower arm stays out of itself with self_collision on and passes through
// itself with it off; a body at rest, moved rigidly or shrunk (neighbours closer than the margin,
// facing the same way) has no self-contact rows; the spatial hash finds what a search of every
// pair finds; row keys are unique.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <set>

#include "constraints/deformable_contact_source.h"
#include "constraints/deformable_island_body.h"
#include "constraints/self_contact_search.h"
#include "demos/scenes/bullet_world_holder.h"
#include "plugin/box_tet_mesher.h"
#include "plugin/tet_element_model.h"

namespace taut {
namespace {

constexpr double kStep = 1.0 / 240.0;
constexpr double kMargin = 0.005;  // [m] contact margin: rest exclusion radius 1 cm

// A hairpin in x: a 0.6 x 0.1 x 0.12 m box of 12 x 2 x 6 cells whose layer 3 (z in [0.06, 0.08])
// is cut out beyond x = 0.1 m, leaving a 6 cm lower arm and a 4 cm upper arm, 2 cm apart, joined
// at x < 0.1 m (the fold). Slightly above the ground z = 0.
TetMesh MakeHairpinMesh() {
  const TetMesh box = MakeBoxTetMesh(Vec3(0.6, 0.1, 0.12), 12, 2, 6, Vec3(0.0, -0.05, 1e-4));
  TetMesh hairpin;
  hairpin.nodes = box.nodes;  // every node is still used: the slot is one layer
  hairpin.source = "hairpin";
  for (const auto& tet : box.tets) {
    Vec3 centre = Vec3::Zero();
    for (int n : tet) centre += box.nodes[n] / 4.0;
    const bool in_slot = centre.x() > 0.1 && centre.z() > 0.06 + 1e-4 && centre.z() < 0.08 + 1e-4;
    if (!in_slot) hairpin.tets.push_back(tet);
  }
  return hairpin;
}

// Settings of the soft hairpin (E = 1 MPa: the upper arm's linear cantilever sag, 1.5 rho g L^4 /
// (E t^2) = 0.57 m, is far more than the 2 cm slot).
DeformableBodySettings HairpinSettings(bool self_collision) {
  DeformableBodySettings settings;
  settings.name = "hairpin";
  settings.material = {1e6, 0.3, 1000.0};
  settings.mass_damping = 4.0;
  settings.contact_margin = kMargin;
  settings.self_collision = self_collision;
  return settings;
}

// Barycentric coordinates of p in tet (a, b, c, d): p = a + l1 (b - a) + l2 (c - a) + l3 (d - a).
Vec3 CalcTetCoordinates(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  Mat3 edges;
  edges << b - a, c - a, d - a;
  return edges.fullPivLu().solve(p - a);
}

// Deepest boundary node of the body inside its own material at positions x [m]: a node strictly
// inside a tet it is not a node of lies that deep below the nearest boundary triangle it is not a
// corner of (the signed distance to its own surface, elsewhere); 0 when none is inside.
double CalcSelfPenetration(const TetMesh& mesh, const VecX& x) {
  const ContactSurface surface = MakeTetContactSurface(mesh);
  auto at = [&](int node) { return Vec3(x.segment<3>(3 * node)); };
  double deepest = 0.0;
  for (const ContactPoint& point : surface.points) {
    const int node = point.nodes[0];
    const Vec3 p = at(node);
    bool inside = false;
    for (const auto& tet : mesh.tets) {
      if (std::find(tet.begin(), tet.end(), node) != tet.end()) continue;
      const Vec3 l = CalcTetCoordinates(p, at(tet[0]), at(tet[1]), at(tet[2]), at(tet[3]));
      if (l.minCoeff() > 1e-9 && l.sum() < 1.0 - 1e-9) {
        inside = true;
        break;
      }
    }
    if (!inside) continue;
    double depth = HUGE_VAL;
    for (const Triangle& t : surface.triangles) {
      const int a = surface.points[t[0]].nodes[0], b = surface.points[t[1]].nodes[0],
                c = surface.points[t[2]].nodes[0];
      if (a == node || b == node || c == node) continue;
      const Vec3 beta = internal::CalcNearestTrianglePoint(p, at(a), at(b), at(c));
      depth = std::min(depth, (p - (beta[0] * at(a) + beta[1] * at(b) + beta[2] * at(c))).norm());
    }
    deepest = std::max(deepest, depth);
  }
  return deepest;
}

// The hairpin clamped at its fold end (x = 0) on a static ground, under gravity, for `steps`.
struct SaggingHairpin {
  BulletWorldHolder holder;
  TetMesh mesh = MakeHairpinMesh();
  DeformableBody* body = nullptr;
  double worst = 0.0;  // deepest self-penetration seen [m]
  int max_contact_rows = 0;

  explicit SaggingHairpin(bool self_collision) {
    holder.AddStaticGround(1.0);
    body = holder.world.AddTetBody(mesh, HairpinSettings(self_collision));
    body->FixNodesWhere([](const Vec3& X) { return X.x() < 1e-9; });
  }
  void Run(int steps) {
    for (int i = 0; i < steps; ++i) {
      holder.world.stepSimulation(kStep, 1, kStep);
      max_contact_rows = std::max(max_contact_rows, holder.world.last_step_stats().rows_contact);
      if (i % 10 == 9) worst = std::max(worst, CalcSelfPenetration(mesh, body->x()));
    }
  }
  // Lowest z of the upper arm's top face (rest z = 0.12 m) [m].
  double CalcUpperArmLowestTop() const {
    double z = HUGE_VAL;
    for (int n = 0; n < body->num_nodes(); ++n)
      if (mesh.nodes[n].z() > 0.12) z = std::min(z, body->node_position(n).z());
    return z;
  }
};

TEST(SelfCollisionTest, SaggingArmOfAHairpinRestsOnTheOtherArmInsteadOfPassingThrough) {
  SaggingHairpin on(true), off(false);
  on.Run(240);
  off.Run(240);
  const double final_on = CalcSelfPenetration(on.mesh, on.body->x());
  const double final_off = CalcSelfPenetration(off.mesh, off.body->x());
  std::printf(
      "hairpin after 1 s: self_collision on: deepest self-penetration %.2e m (worst %.2e m), upper "
      "arm top down to %.4f m, contact rows %d; off: %.2e m, upper arm top down to %.4f m\n",
      final_on, on.worst, on.CalcUpperArmLowestTop(), on.max_contact_rows, final_off,
      off.CalcUpperArmLowestTop());
  // Off: the upper arm (4 cm) sinks into the lower one (6 cm, top at 6 cm).
  EXPECT_GT(final_off, 0.01);
  EXPECT_LT(off.CalcUpperArmLowestTop(), 0.06);
  // On: it lies on the lower arm (upper arm top at >= 6 + 4 cm, less the compression), and no
  // boundary node is more than 0.5 mm inside the body at any checked step.
  EXPECT_LT(on.worst, 5e-4);
  EXPECT_GT(on.CalcUpperArmLowestTop(), 0.095);
  EXPECT_GT(on.max_contact_rows, 0);
}

// Normal rows a self-contact source emits for `body` at positions x.
std::vector<ConstraintRow> CalcSelfRows(DeformableBody& body, const VecX& x, double margin) {
  DeformableContactSource source(body, MakeBodyContactSurface(body.model()), 1, 0.25, margin);
  DeformableIslandBody island_body(body);
  const std::vector<IslandBody*> bodies = {&island_body};
  const std::vector<VecX> v = {body.v()}, xs = {x};
  std::vector<ConstraintRow> rows;
  source.AppendIslandRows(IslandIterate(kStep, bodies, v, xs), rows);
  return rows;
}

// A body of `mesh` (not in a world) with `settings`.
DeformableBody MakeBody(const TetMesh& mesh, const DeformableBodySettings& settings) {
  return DeformableBody(
      std::make_unique<TetElementModel>(std::make_shared<const TetMesh>(mesh), settings.material),
      settings);
}

TEST(SelfCollisionTest, BodyAtRestMovedRigidlyOrShrunkHasNoSelfContactRows) {
  // A fine cube: 1 cm cells, as long as the 1 cm margin, so surface neighbours two and three
  // cells away are within the rest exclusion (2 cm) and beyond it, both at rest and shrunk.
  DeformableBodySettings settings = HairpinSettings(true);
  settings.contact_margin = 0.01;
  DeformableBody cube = MakeBody(MakeBoxTetMesh(Vec3(0.1, 0.1, 0.1), 10, 10, 10), settings);
  const VecX rest = cube.x();
  Mat3 rotation = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  VecX moved = rest, shrunk = rest;
  for (int n = 0; n < cube.num_nodes(); ++n) {
    moved.segment<3>(3 * n) = rotation * rest.segment<3>(3 * n) + Vec3(0.3, -2.0, 5.0);
    shrunk.segment<3>(3 * n) = 0.4 * rest.segment<3>(3 * n);  // neighbours at 2-3 cm now 8-12 mm
  }
  const SelfContactSearch search(cube, MakeBodyContactSurface(cube.model()), 0.01);
  std::printf("fine cube: %d rest-excluded (point, triangle) pairs\n", search.num_excluded_pairs());
  EXPECT_GT(search.num_excluded_pairs(), 0);
  EXPECT_EQ(CalcSelfRows(cube, rest, 0.01).size(), 0u);
  EXPECT_EQ(CalcSelfRows(cube, moved, 0.01).size(), 0u);
  EXPECT_EQ(CalcSelfRows(cube, shrunk, 0.01).size(), 0u);

  // The hairpin at rest in a world without gravity: its facing slot faces are 2 cm apart, 4
  // margins; no rows, no solve.
  BulletWorldHolder holder;
  holder.world.setGravity(btVector3(0, 0, 0));
  DeformableBody* hairpin = holder.world.AddTetBody(MakeHairpinMesh(), HairpinSettings(true));
  for (int i = 0; i < 5; ++i) {
    holder.world.stepSimulation(kStep, 1, kStep);
    EXPECT_EQ(holder.world.last_step_stats().rows_contact, 0) << "step " << i;
  }
  EXPECT_LT(hairpin->v().cwiseAbs().maxCoeff(), 1e-9);  // at rest: round-off forces only
}

// The hairpin with its upper arm moved down by `drop` [m] and every node jiggled by up to
// `noise` [m]: positions with many self-contacts.
VecX MakePressedHairpin(const DeformableBody& body, const TetMesh& mesh, double drop, double noise,
                        unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-noise, noise);
  VecX x = body.x();
  for (int n = 0; n < body.num_nodes(); ++n) {
    if (mesh.nodes[n].z() > 0.08 - 1e-9 + 1e-4 && mesh.nodes[n].x() > 0.1 + 1e-9)
      x[3 * n + 2] -= drop;
    for (int a = 0; a < 3; ++a) x[3 * n + a] += u(rng);
  }
  return x;
}

TEST(SelfCollisionTest, SpatialHashFindsTheHitsOfASearchOverEveryPair) {
  const TetMesh mesh = MakeHairpinMesh();
  DeformableBody body = MakeBody(mesh, HairpinSettings(true));
  const ContactSurface surface = MakeBodyContactSurface(body.model());
  const SelfContactSearch search(body, surface, kMargin);
  for (unsigned seed = 1; seed <= 3; ++seed) {
    const VecX x = MakePressedHairpin(body, mesh, 0.02, 3e-3, seed);
    std::vector<SelfContactSearch::Hit> hits;
    search.FindHits(x, hits);
    // Every pair: the same rules (rest exclusion, facing, margin), nearest triangle per point.
    auto at = [&](int point) { return Vec3(x.segment<3>(3 * surface.points[point].nodes[0])); };
    std::vector<Vec3> point_normals(surface.points.size(), Vec3::Zero());
    for (const Triangle& t : surface.triangles)
      for (int corner : t)
        point_normals[corner] += (at(t[1]) - at(t[0])).cross(at(t[2]) - at(t[0]));
    std::vector<SelfContactSearch::Hit> expected;
    for (int i = 0; i < static_cast<int>(surface.points.size()); ++i) {
      double best = kMargin;
      SelfContactSearch::Hit hit{-1, -1, Vec3::Zero(), Vec3::Zero(), 0.0};
      for (int t = 0; t < static_cast<int>(surface.triangles.size()); ++t) {
        const Triangle& tri = surface.triangles[t];
        const Vec3 normal = (at(tri[1]) - at(tri[0])).cross(at(tri[2]) - at(tri[0]));
        if (point_normals[i].dot(normal) >= 0.0 || search.IsExcluded(i, t)) continue;
        const Vec3 beta =
            internal::CalcNearestTrianglePoint(at(i), at(tri[0]), at(tri[1]), at(tri[2]));
        const Vec3 q = beta[0] * at(tri[0]) + beta[1] * at(tri[1]) + beta[2] * at(tri[2]);
        if ((at(i) - q).norm() >= best) continue;
        best = (at(i) - q).norm();
        hit = {i, t, normal.normalized(), beta, normal.normalized().dot(at(i) - q)};
      }
      if (hit.triangle >= 0) expected.push_back(hit);
    }
    std::printf("pressed hairpin (seed %u): %zu self-contacts, every-pair search %zu\n", seed,
                hits.size(), expected.size());
    ASSERT_GT(expected.size(), 20u);
    ASSERT_EQ(hits.size(), expected.size());
    for (size_t k = 0; k < hits.size(); ++k) {
      EXPECT_EQ(hits[k].point, expected[k].point);
      EXPECT_EQ(hits[k].triangle, expected[k].triangle);
      EXPECT_NEAR(hits[k].gap, expected[k].gap, 1e-15);
    }
  }
}

TEST(SelfCollisionTest, RowsOfAPressedHairpinHaveUniqueKeysAndActOnTheBodyAsBothSides) {
  const TetMesh mesh = MakeHairpinMesh();
  DeformableBody body = MakeBody(mesh, HairpinSettings(true));
  const std::vector<ConstraintRow> rows =
      CalcSelfRows(body, MakePressedHairpin(body, mesh, 0.02, 3e-3, 4), kMargin);
  ASSERT_GT(rows.size(), 3u * 20u);
  std::set<std::uint64_t> keys;
  for (const ConstraintRow& row : rows) {
    EXPECT_TRUE(keys.insert(row.key).second) << "duplicate key " << row.key;
    EXPECT_EQ(row.body, 0);
    EXPECT_EQ(row.body2, 0);
    EXPECT_EQ(row.type, RowType::kContact);
    for (int n = 0; n < row.num_nodes2; ++n) EXPECT_NE(row.nodes2[n], row.nodes[0]);
  }
  EXPECT_EQ(rows.size() % 3, 0u);  // a normal and two friction rows per contact
}

TEST(SelfCollisionTest, SearchCostGrowsLinearlyWithTheSurface) {
  // Beams of 0.4 m and 4 m (about 9 times the surface: 5k triangles): the hash's work per call
  // grows about as the surface, where a search over every pair would grow 9 times faster still.
  // The bound is loose (timing on a shared machine).
  auto time_call = [](int n) {
    DeformableBody beam =
        MakeBody(MakeBoxTetMesh(Vec3(0.1 * n, 0.1, 0.1), 4 * n, 4, 4), HairpinSettings(true));
    const ContactSurface surface = MakeBodyContactSurface(beam.model());
    const SelfContactSearch search(beam, surface, 0.01);
    std::vector<SelfContactSearch::Hit> hits;
    double ms = HUGE_VAL;  // the fastest of 20 calls: the least disturbed by other load
    for (int k = 0; k < 20; ++k) {
      const auto start = std::chrono::steady_clock::now();
      search.FindHits(beam.x(), hits);
      ms = std::min(
          ms, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                  .count());
    }
    std::printf("beam of %zu surface triangles: %.3f ms per self-contact search\n",
                surface.triangles.size(), ms);
    return std::make_pair(static_cast<double>(surface.triangles.size()), ms);
  };
  const auto [small_triangles, small_ms] = time_call(4);
  const auto [large_triangles, large_ms] = time_call(40);
  const double growth = (large_ms / small_ms) / (large_triangles / small_triangles);
  std::printf("time ratio over surface ratio: %.2f (every pair: ~%.0f)\n", growth,
              large_triangles / small_triangles);
  EXPECT_LT(growth, 2.5);
}

}  // namespace
}  // namespace taut
