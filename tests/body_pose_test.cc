// AddTetBody / AddHexBody with a pose: the body starts at the posed rest mesh, at rest, and moves
// as the unposed body carried by the pose.
#include <btBulletDynamicsCommon.h>
#include <gtest/gtest.h>

#include "bullet_bridge/deformable_world.h"
#include "bullet_bridge/eigen_bullet.h"
#include "plugin/box_tet_mesher.h"

namespace taut {
namespace {

// A DeformableWorld with Bullet's default parts and gravity g [m/s^2].
struct BulletParts {
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher{&configuration};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  DeformableWorld world{&dispatcher, &broadphase, &solver, &configuration};
  explicit BulletParts(const Vec3& g) { world.setGravity(ToBullet(g)); }
};

DeformableBodySettings MakeSettings() {
  DeformableBodySettings settings;
  settings.name = "beam";
  settings.material = {2e5, 0.3, 1000.0};
  return settings;
}

// A rotation that mixes every axis, and a translation [m].
btTransform MakePose() {
  return btTransform(btQuaternion(btVector3(1, 2, 3).normalized(), 0.7), btVector3(0.5, -2, 3));
}

// |x_i - pose * X_i| over the nodes of `body` [m], X the rest positions.
double CalcPoseError(const DeformableBody& body, const btTransform& pose) {
  const Mat3 R = ToEigen(pose.getBasis());
  const Vec3 t = ToEigen(pose.getOrigin());
  double error = 0.0;
  for (int i = 0; i < body.num_nodes(); ++i) {
    const Vec3 X = body.model().rest_positions().segment<3>(3 * i);
    error = std::max(error, (body.node_position(i) - (R * X + t)).norm());
  }
  return error;
}

TEST(BodyPoseTest, PosedTetBodyStartsAtTheTransformedMeshAtRest) {
  BulletParts bullet(Vec3::Zero());
  const TetMesh mesh = MakeBoxTetMesh(Vec3(0.4, 0.1, 0.1), 4, 1, 1);
  const btTransform pose = MakePose();
  DeformableBody* body = bullet.world.AddTetBody(mesh, MakeSettings(), pose);
  EXPECT_LT(CalcPoseError(*body, pose), 1e-15);
  // The rest mesh is kept as given.
  for (size_t i = 0; i < mesh.nodes.size(); ++i)
    EXPECT_EQ(body->rest_tet_mesh()->nodes[i], mesh.nodes[i]);
  // At rest there: no elastic energy, and a step without gravity moves nothing.
  EXPECT_LT(body->CalcElasticEnergy(), 1e-24);
  bullet.world.stepSimulation(1.0 / 240.0, 1, 1.0 / 240.0);
  EXPECT_LT(body->v().cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT(CalcPoseError(*body, pose), 1e-14);
}

TEST(BodyPoseTest, PosedHexBodyStartsAtTheTransformedLatticeAtRest) {
  BulletParts bullet(Vec3::Zero());
  const btTransform pose = MakePose();
  DeformableBody* body = bullet.world.AddHexBody(
      std::make_shared<const HexLattice>(MakeBoxHexLattice(Vec3(0.4, 0.1, 0.1), 4, 1, 1)),
      MakeSettings(), pose);
  EXPECT_LT(CalcPoseError(*body, pose), 1e-15);
  EXPECT_LT(body->CalcElasticEnergy(), 1e-24);
  bullet.world.stepSimulation(1.0 / 240.0, 1, 1.0 / 240.0);
  EXPECT_LT(body->v().cwiseAbs().maxCoeff(), 1e-12);
}

TEST(BodyPoseTest, PosedCantileverMovesAsTheUnposedOneCarriedByThePose) {
  // The same clamped beam sagging under gravity, once in the mesh frame and once posed with the
  // gravity turned by the pose: x_posed = R x + t at every step.
  const btTransform pose = MakePose();
  const Mat3 R = ToEigen(pose.getBasis());
  const Vec3 t = ToEigen(pose.getOrigin());
  const Vec3 g(0, 0, -9.81);
  BulletParts plain(g), posed(R * g);
  const auto mesh = std::make_shared<const TetMesh>(MakeBoxTetMesh(Vec3(0.4, 0.1, 0.1), 8, 2, 2));
  DeformableBody* a = plain.world.AddTetBody(mesh, MakeSettings());
  DeformableBody* b = posed.world.AddTetBody(mesh, MakeSettings(), pose);
  // FixNodesWhere sees rest positions, which the pose leaves in the mesh frame.
  const auto clamped = [](const Vec3& X) { return X.x() < 1e-9; };
  ASSERT_EQ(a->FixNodesWhere(clamped), 9);
  ASSERT_EQ(b->FixNodesWhere(clamped), 9);
  for (int step = 0; step < 20; ++step) {
    plain.world.stepSimulation(1.0 / 240.0, 1, 1.0 / 240.0);
    posed.world.stepSimulation(1.0 / 240.0, 1, 1.0 / 240.0);
    for (int i = 0; i < a->num_nodes(); ++i) {
      ASSERT_LT((b->node_position(i) - (R * a->node_position(i) + t)).norm(), 1e-9)
          << "step " << step << " node " << i;
      ASSERT_LT((b->v().segment<3>(3 * i) - R * a->v().segment<3>(3 * i)).norm(), 1e-9);
    }
  }
  // The beam really sagged (the tip fell by more than 1 mm).
  const int tip = BoxNodeIndex(8, 0, 0, 8, 2);
  EXPECT_LT(a->node_position(tip).z(), -1e-3);
}

TEST(BodyPoseTest, PoseThatIsNotARotationIsRejectedBeforeAnythingIsAdded) {
  BulletParts bullet(Vec3::Zero());
  btTransform scaled = MakePose();
  scaled.setBasis(scaled.getBasis().scaled(btVector3(1, 1, 1.01)));
  const TetMesh mesh = MakeBoxTetMesh(Vec3(0.4, 0.1, 0.1), 4, 1, 1);
  EXPECT_THROW(bullet.world.AddTetBody(mesh, MakeSettings(), scaled), InputError);
  btTransform mirrored = btTransform::getIdentity();
  mirrored.setBasis(btMatrix3x3(1, 0, 0, 0, 1, 0, 0, 0, -1));
  EXPECT_THROW(bullet.world.AddTetBody(mesh, MakeSettings(), mirrored), InputError);
  EXPECT_EQ(bullet.world.num_deformable_bodies(), 0);
}

}  // namespace
}  // namespace taut
