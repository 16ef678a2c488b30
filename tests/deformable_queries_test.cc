#include "bullet_bridge/deformable_queries.h"

#include <btBulletDynamicsCommon.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include "plugin/box_tet_mesher.h"
#include "plugin/hex_lattice.h"
#include "plugin/surface_hit_element.h"
#include "tests/block_world.h"

namespace taut {
namespace {

// Block [0, 0.4] x [0, 0.3] x [0.1, 0.3] m: its top face is at z = 0.3, its bottom at z = 0.1.
constexpr double kTop = 0.3, kBottom = 0.1;
const Vec3 kSize(0.4, 0.3, 0.2), kCorner(0, 0, 0.1);

// A world without gravity holding one tet block "block" at rest, and rigid objects on demand.
struct BlockScene : BlockWorld {
  BlockScene() : BlockWorld(MakeBoxTetMesh(kSize, 2, 2, 1, kCorner), btVector3(0, 0, 0)) {}
};

// A vertical ray at (x, y) from z = 1 down to z = -1; hits at z have fraction (1 - z) / 2.
const btVector3 kFrom(0.1313, 0.0717, 1.0), kTo(0.1313, 0.0717, -1.0);

TEST(DeformableQueriesTest, RayDownHitsTopFaceAtItsHeightWithUpNormalAndItsElement) {
  BlockScene scene;
  const auto hit = RayTestDeformables(scene.world, kFrom, kTo);
  ASSERT_TRUE(hit.has_value());
  EXPECT_EQ(hit->body, scene.block);
  EXPECT_EQ(hit->object, &scene.BlockObject());
  EXPECT_NEAR(hit->point.z(), kTop, 1e-9);
  EXPECT_NEAR(hit->point.x(), 0.1313, 1e-12);
  EXPECT_NEAR(hit->fraction, (1.0 - kTop) / 2.0, 1e-9);
  EXPECT_NEAR((hit->normal - Vec3(0, 0, 1)).norm(), 0.0, 1e-12);
  // The element is a tet of the block that contains the hit point (on its top face).
  ASSERT_GE(hit->element, 0);
  ASSERT_LT(hit->element, scene.block->num_elements());
  const int* n = scene.block->model().element_nodes(hit->element);
  const auto& x = *scene.block;
  const Eigen::Vector4d l =
      internal::CalcTetBarycentric(hit->point, x.node_position(n[0]), x.node_position(n[1]),
                                   x.node_position(n[2]), x.node_position(n[3]));
  EXPECT_GE(l.minCoeff(), -1e-9) << l.transpose();
  EXPECT_GE(hit->triangle, 0);
}

TEST(DeformableQueriesTest, RayThatMissesReportsNoHit) {
  BlockScene scene;
  EXPECT_FALSE(RayTestDeformables(scene.world, btVector3(5, 0.1, 1), btVector3(5, 0.1, -1)));
  // A segment that stops above the block.
  EXPECT_FALSE(RayTestDeformables(scene.world, kFrom, btVector3(0.1313, 0.0717, 0.31)));
  EXPECT_TRUE(
      RayTestAllDeformables(scene.world, btVector3(5, 0.1, 1), btVector3(5, 0.1, -1)).empty());
}

TEST(DeformableQueriesTest, RayThroughTheBlockEntersAtTheTopAndLeavesAtTheBottom) {
  BlockScene scene;
  const std::vector<DeformableRayHit> hits = RayTestAllDeformables(scene.world, kFrom, kTo);
  ASSERT_EQ(hits.size(), 2u);
  EXPECT_NEAR(hits[0].point.z(), kTop, 1e-9);
  EXPECT_NEAR(hits[1].point.z(), kBottom, 1e-9);
  EXPECT_NEAR((hits[0].normal - Vec3(0, 0, 1)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((hits[1].normal - Vec3(0, 0, -1)).norm(), 0.0, 1e-12);
  EXPECT_LT(hits[0].fraction, hits[1].fraction);
  EXPECT_GE(hits[1].element, 0);
}

TEST(DeformableQueriesTest, RayOnASharedDiagonalIsReportedOnce) {
  BlockScene scene;
  // (0.1, 0.075) lies on the diagonal of the top-face cell [0, 0.2] x [0, 0.15].
  const auto hits =
      RayTestAllDeformables(scene.world, btVector3(0.1, 0.075, 1), btVector3(0.1, 0.075, -1));
  ASSERT_EQ(hits.size(), 2u);
  EXPECT_NEAR(hits[0].point.z(), kTop, 1e-9);
}

TEST(DeformableQueriesTest, HitFollowsTheDeformedSurface) {
  BlockScene scene;
  VecX x = scene.block->x();
  for (int i = 0; i < scene.block->num_nodes(); ++i)
    if (x[3 * i + 2] > kTop - 1e-9) x[3 * i + 2] += 0.05;  // lift the top face by 5 cm
  scene.block->set_x(x);
  const auto hit = RayTestDeformables(scene.world, kFrom, kTo);
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(hit->point.z(), kTop + 0.05, 1e-9);
  EXPECT_NEAR((hit->normal - Vec3(0, 0, 1)).norm(), 0.0, 1e-12);
}

TEST(DeformableQueriesTest, GroupAndMaskThatExcludeTheBlockMakeTheRayMiss) {
  BlockScene scene;
  constexpr int kBlockGroup = 64;
  scene.BlockObject().getBroadphaseHandle()->m_collisionFilterGroup = kBlockGroup;
  QueryFilter filter;
  filter.mask = btBroadphaseProxy::AllFilter & ~kBlockGroup;
  EXPECT_FALSE(RayTestDeformables(scene.world, kFrom, kTo, filter));
  filter.mask = btBroadphaseProxy::AllFilter;
  EXPECT_TRUE(RayTestDeformables(scene.world, kFrom, kTo, filter));
  // The block's own mask excluding the query's group hides it too.
  scene.BlockObject().getBroadphaseHandle()->m_collisionFilterMask = kBlockGroup;
  EXPECT_FALSE(RayTestDeformables(scene.world, kFrom, kTo));
}

TEST(DeformableQueriesTest, BulletCallbackGetsTheClosestOfRigidAndDeformableHits) {
  BlockScene scene;
  btCollisionObject* ground = scene.AddObject(new btBoxShape(btVector3(1, 1, 0.05)),
                                              btVector3(0, 0, 0));  // top at z = 0.05
  btCollisionWorld::ClosestRayResultCallback closest(kFrom, kTo);
  scene.world.rayTest(kFrom, kTo, closest);
  ASSERT_EQ(closest.m_collisionObject, ground);  // Bullet alone cannot see the block
  RayTestDeformables(scene.world, kFrom, kTo, closest);
  EXPECT_EQ(closest.m_collisionObject, &scene.BlockObject());
  EXPECT_NEAR(closest.m_hitPointWorld.z(), kTop, 1e-9);
  EXPECT_NEAR(closest.m_hitNormalWorld.z(), 1.0, 1e-12);
  // A callback whose mask leaves out the block's group keeps the ground.
  scene.BlockObject().getBroadphaseHandle()->m_collisionFilterGroup = 64;
  btCollisionWorld::ClosestRayResultCallback masked(kFrom, kTo);
  masked.m_collisionFilterMask = btBroadphaseProxy::AllFilter & ~64;
  scene.world.rayTest(kFrom, kTo, masked);
  RayTestDeformables(scene.world, kFrom, kTo, masked);
  EXPECT_EQ(masked.m_collisionObject, ground);
  // All hits: the block's two and the ground's one.
  btCollisionWorld::AllHitsRayResultCallback all(kFrom, kTo);
  scene.world.rayTest(kFrom, kTo, all);
  RayTestDeformables(scene.world, kFrom, kTo, all);
  EXPECT_EQ(all.m_collisionObjects.size(), 3);
}

TEST(DeformableQueriesTest, ContactTestListsPointsOfASpherePressedIntoTheBlock) {
  BlockScene scene;
  // Sphere r = 0.1 centred 0.07 above the top-face node (0.2, 0.15, 0.3): 3 cm deep there.
  btCollisionObject* pressed =
      scene.AddObject(new btSphereShape(0.1), btVector3(0.2, 0.15, kTop + 0.07));
  const std::vector<DeformableContactHit> hits = ContactTestDeformables(scene.world, *pressed);
  ASSERT_FALSE(hits.empty());
  bool centre_found = false;
  for (const DeformableContactHit& hit : hits) {
    EXPECT_GT(hit.depth, 0.0);
    EXPECT_EQ(hit.body, scene.block);
    EXPECT_GE(hit.node, 0);
    if ((hit.position - Vec3(0.2, 0.15, kTop)).norm() < 1e-12) {
      centre_found = true;
      EXPECT_NEAR(hit.depth, 0.03, 1e-12);
      EXPECT_NEAR((hit.normal - Vec3(0, 0, -1)).norm(), 0.0, 1e-12);
      EXPECT_NEAR(hit.point_on_shape.z(), kTop + 0.07 - 0.1, 1e-12);
    }
  }
  EXPECT_TRUE(centre_found);
  btCollisionObject* distant = scene.AddObject(new btSphereShape(0.1), btVector3(2, 2, 2));
  EXPECT_TRUE(ContactTestDeformables(scene.world, *distant).empty());
  EXPECT_TRUE(ContactTestDeformables(scene.world, *distant, 0.5).empty());
  // Within a larger gap the distant sphere is still too far; the pressed one gains neighbours.
  EXPECT_GE(ContactTestDeformables(scene.world, *pressed, 0.2).size(), hits.size());
}

TEST(DeformableQueriesTest, ContactTestRespectsGroupsAndMasks) {
  BlockScene scene;
  const btVector3 centre(0.2, 0.15, kTop + 0.07);
  btCollisionObject* masked =
      scene.AddObject(new btSphereShape(0.1), centre, 2, btBroadphaseProxy::AllFilter & ~1);
  EXPECT_TRUE(ContactTestDeformables(scene.world, *masked).empty());  // its mask: not group 1
  EXPECT_FALSE(ContactTestDeformables(scene.world, *masked, 0.0, QueryFilter{}).empty());
  EXPECT_TRUE(ContactTestDeformables(scene.world, *masked, 0.0, QueryFilter{1, 2}).empty());
  EXPECT_THROW(ContactTestDeformables(scene.world, *masked, -1.0), InputError);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(RayTestDeformables(scene.world, btVector3(nan, 0, 0), kTo), InputError);
}

TEST(DeformableQueriesTest, RayOnAHexBodyReportsItsTopHex) {
  BlockScene scene;
  DeformableBodySettings settings;
  settings.name = "hexes";
  settings.material = {1e5, 0.3, 1000};
  DeformableBody* hexes =
      scene.world.AddHexBody(MakeBoxHexLattice(kSize, 2, 2, 2, Vec3(2, 0, 0.1)), settings);
  const auto hit =
      RayTestDeformables(scene.world, btVector3(2.31, 0.2, 1), btVector3(2.31, 0.2, -1));
  ASSERT_TRUE(hit.has_value());
  EXPECT_EQ(hit->body, hexes);
  EXPECT_NEAR(hit->point.z(), kTop, 1e-9);
  // The top-layer hex over x in [0.2, 0.4], y in [0.15, 0.3]: its node centroid.
  ASSERT_GE(hit->element, 0);
  Vec3 centroid = Vec3::Zero();
  for (int a = 0; a < 8; ++a)
    centroid += hexes->node_position(hexes->model().element_nodes(hit->element)[a]) / 8.0;
  EXPECT_NEAR((centroid - Vec3(2.3, 0.225, 0.25)).norm(), 0.0, 1e-12);
}

// A free-floating body without gravity or damping, at rest.
TEST(DeformableQueriesTest, NodeForceForOneStepChangesVelocityByHForceOverMass) {
  BlockScene scene;
  DeformableBody& body = *scene.block;
  const double h = 1.0 / 240.0;
  // Every node pushed with the same acceleration a: f_i = m_i a, so v_i = h f_i / m_i = h a
  // (a translation is in the null space of K).
  const Vec3 a(0.3, -1.2, 2.5);
  for (int i = 0; i < body.num_nodes(); ++i) body.AddNodeForce(i, body.node_mass(i) * a);
  EXPECT_NEAR((body.node_external_force(1) - body.node_mass(1) * a).norm(), 0.0, 1e-15);
  scene.world.stepSimulation(h, 1, h);
  for (int i = 0; i < body.num_nodes(); ++i) {
    const Vec3 expected = h * (body.node_mass(i) * a) / body.node_mass(i);  // h f_i / m_i
    EXPECT_LT((body.node_velocity(i) - expected).norm(), 1e-9 * expected.norm()) << "node " << i;
  }
  EXPECT_EQ(body.node_external_force(0), Vec3::Zero());
  // Forces last one step: the next step keeps the velocity.
  scene.world.stepSimulation(h, 1, h);
  EXPECT_LT((body.node_velocity(3) - h * a).norm(), 1e-9 * (h * a).norm());
}

TEST(DeformableQueriesTest, SingleNodeForceGivesTheBodyMomentumHForce) {
  BlockScene scene;
  DeformableBody& body = *scene.block;
  const double h = 1.0 / 240.0;
  const Vec3 f(0.0, 0.0, -4.0);  // [N] on one top node
  body.AddNodeForce(7, f);
  scene.world.stepSimulation(h, 1, h);
  Vec3 momentum = Vec3::Zero();
  for (int i = 0; i < body.num_nodes(); ++i) momentum += body.node_mass(i) * body.node_velocity(i);
  EXPECT_LT((momentum - h * f).norm(), 1e-9 * (h * f).norm());
  // The pushed node moves most, in the force's direction.
  EXPECT_LT(body.node_velocity(7).z(), 0.0);
}

TEST(DeformableQueriesTest, BadNodeIndexOrForceThrowsNamingBodyAndIndexAndKeepsState) {
  BlockScene scene;
  DeformableBody& body = *scene.block;
  const int n = body.num_nodes();
  body.AddNodeForce(2, Vec3(1, 0, 0));
  const VecX x = body.x(), v = body.v();
  const auto expect_error = [](const std::function<void()>& fn, const std::string& index) {
    try {
      fn();
      ADD_FAILURE() << "no InputError for index " << index;
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("body 'block'"), std::string::npos) << what;
      EXPECT_NE(what.find("node " + index), std::string::npos) << what;
    }
  };
  expect_error([&] { body.node_position(n); }, std::to_string(n));
  expect_error([&] { body.node_velocity(-1); }, "-1");
  expect_error([&] { body.node_mass(n + 5); }, std::to_string(n + 5));
  expect_error([&] { body.node_external_force(-3); }, "-3");
  expect_error([&] { body.AddNodeForce(n, Vec3(1, 0, 0)); }, std::to_string(n));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  expect_error([&] { body.AddNodeForce(4, Vec3(nan, 0, 0)); }, "4");
  EXPECT_EQ(body.x(), x);
  EXPECT_EQ(body.v(), v);
  EXPECT_EQ(body.node_external_force(2), Vec3(1, 0, 0));
  EXPECT_EQ(body.node_external_force(4), Vec3::Zero());
}

}  // namespace
}  // namespace taut
