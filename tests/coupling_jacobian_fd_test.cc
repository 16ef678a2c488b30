// Central finite differences of the coupling rows' Jacobians: for a row, C at velocities
// v + d e_k minus C at v - d e_k, over 2d, equals h J_k (the rows' J is dC/dx, x = x0 + h v; a
// rigid body's blocks are (v, omega), integrated by Bullet's exponential map). Checked at omega = 0
// where the map's derivative is exactly h (r x .).
#include <btBulletDynamicsCommon.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>

#include "bullet_bridge/eigen_bullet.h"
#include "bullet_bridge/node_attachment_source.h"
#include "bullet_bridge/rigid_contact_source.h"
#include "constraints/deformable_contact_source.h"
#include "constraints/deformable_island_body.h"
#include "plugin/box_tet_mesher.h"
#include "plugin/tet_element_model.h"

namespace taut {
namespace {

constexpr double kH = 0.01;

// A free deformable cube of 0.2 m with its step begun (x0 set), optionally offset.
std::unique_ptr<DeformableBody> MakeCube(const Vec3& corner, const std::string& name) {
  DeformableBodySettings settings;
  settings.name = name;
  settings.material = {1e5, 0.3, 1000.0};
  auto mesh = std::make_shared<const TetMesh>(MakeBoxTetMesh(Vec3(0.2, 0.2, 0.2), 1, 1, 1, corner));
  auto body = std::make_unique<DeformableBody>(
      std::make_unique<TetElementModel>(mesh, settings.material), settings);
  body->BeginStep(kH, Vec3::Zero());
  return body;
}

// Compares every row's J (both sides) with central differences of `row_c(v)` (the C of row r at
// velocities v, found by key) and returns the largest relative error; each derivative entry is
// checked only when the row exists on both sides of the difference.
double CheckRows(const std::vector<IslandBody*>& bodies, std::vector<VecX> v,
                 ConstraintSource& source, int* rows_checked) {
  std::vector<VecX> x(bodies.size());
  auto evaluate = [&](const std::vector<VecX>& vel, std::vector<ConstraintRow>& rows) {
    for (size_t b = 0; b < bodies.size(); ++b) bodies[b]->CalcPositions(kH, vel[b], x[b]);
    rows.clear();
    source.AppendIslandRows(IslandIterate(kH, bodies, vel, x), rows);
  };
  std::vector<ConstraintRow> base, plus, minus;
  evaluate(v, base);
  double worst = 0.0;
  *rows_checked = 0;
  const double d = 1e-6;
  for (const ConstraintRow& row : base) {
    if (row.friction_of != 0) continue;  // friction rows carry no C
    ++*rows_checked;
    double scale = 0.0;
    row.ForEachEntry([&](int, int, const Vec3& J) { scale = std::max(scale, J.norm()); });
    row.ForEachEntry([&](int body, int block, const Vec3& J) {
      for (int k = 0; k < 3; ++k) {
        std::vector<VecX> vp = v, vm = v;
        vp[body][3 * block + k] += d;
        vm[body][3 * block + k] -= d;
        evaluate(vp, plus);
        evaluate(vm, minus);
        auto find = [&](const std::vector<ConstraintRow>& rows) -> const ConstraintRow* {
          for (const ConstraintRow& r : rows)
            if (r.key == row.key) return &r;
          return nullptr;
        };
        const ConstraintRow* p = find(plus);
        const ConstraintRow* m = find(minus);
        ASSERT_TRUE(p != nullptr && m != nullptr) << "row " << row.key << " vanished";
        const double fd = (p->C - m->C) / (2.0 * d);
        worst = std::max(worst, std::abs(fd - kH * J[k]) / (kH * scale));
      }
    });
  }
  return worst;
}

TEST(CouplingJacobianFdTest, NodeAgainstDynamicRigidBoxMatchesCentralDifferences) {
  std::unique_ptr<DeformableBody> cube = MakeCube(Vec3(-0.1, -0.1, 0.0), "cube");
  btBoxShape shape(btVector3(0.3, 0.3, 0.05));
  btDefaultMotionState state(btTransform(btQuaternion(btVector3(1, 1, 0).normalized(), 0.2),
                                         btVector3(0.02, -0.01, -0.045)));
  btVector3 inertia;
  shape.calculateLocalInertia(2.0, inertia);
  btRigidBody rigid(2.0, &state, &shape, inertia);
  RigidIslandBody box(&rigid);
  box.BeginStep(kH);
  RigidContactSource source(*cube, MakeBodyContactSurface(cube->model()), 1, 0.5, 0.05);
  source.set_partners({{&rigid, &box}});
  DeformableIslandBody flesh(*cube);
  const std::vector<IslandBody*> bodies = {&flesh, &box};
  VecX v_box(6);
  v_box << 0.1, -0.2, 0.3, 0.0, 0.0, 0.0;
  int rows = 0;
  const double worst =
      CheckRows(bodies, {VecX::Constant(3 * cube->num_nodes(), 0.05), v_box}, source, &rows);
  std::printf("node vs dynamic box: %d normal rows, worst relative error %.2e\n", rows, worst);
  EXPECT_GT(rows, 0);
  EXPECT_LT(worst, 1e-6);
}

TEST(CouplingJacobianFdTest, FaceContactAgainstDynamicShapesMatchesCentralDifferences) {
  // A sphere 1 cm into the cube's top face, off its nodes, and a tilted box whose lowest corner
  // is 5 mm into it: face rows (barycentric weights on the triangle's nodes, the shape's deepest
  // point on the rigid side) besides the node rows within the margin.
  std::unique_ptr<DeformableBody> cube = MakeCube(Vec3(0.0, 0.0, 0.0), "pad");
  btSphereShape sphere(0.05);
  btBoxShape box(btVector3(0.02, 0.03, 0.02));
  box.setMargin(0.005);  // below the half extents (Bullet's default 4 cm would invert the core)
  const btTransform poses[] = {
      btTransform(btQuaternion::getIdentity(), btVector3(0.06, 0.13, 0.24)),
      btTransform(btQuaternion(btVector3(1, 2, 0).normalized(), 0.5), btVector3(0.12, 0.07, 0.2))};
  const btCollisionShape* shapes[] = {&sphere, &box};
  for (int s = 0; s < 2; ++s) {
    btCollisionShape* shape = const_cast<btCollisionShape*>(shapes[s]);
    btTransform pose = poses[s];
    if (s == 1) {
      // Lower the box until its deepest corner is 5 mm below the face z = 0.2.
      btVector3 lo, hi;
      shape->getAabb(pose, lo, hi);
      pose.getOrigin().setZ(pose.getOrigin().z() + 0.195 - lo.z());
    }
    btDefaultMotionState state(pose);
    btVector3 inertia;
    shape->calculateLocalInertia(1.0, inertia);
    btRigidBody rigid(1.0, &state, shape, inertia);
    RigidIslandBody body(&rigid);
    body.BeginStep(kH);
    // Margin 3 cm: the closest points lie inside one top triangle, farther than that from the
    // other.
    RigidContactSource source(*cube, MakeBodyContactSurface(cube->model()), 1, 0.5, 0.03);
    source.set_face_contact(true);
    source.set_partners({{&rigid, &body}});
    DeformableIslandBody flesh(*cube);
    VecX v_rigid(6);
    v_rigid << 0.1, -0.2, 0.3, 0.0, 0.0, 0.0;
    VecX v_flesh(3 * cube->num_nodes());
    for (int i = 0; i < cube->num_nodes(); ++i)
      v_flesh.segment<3>(3 * i) = Vec3(0.02 * i, -0.01 * i, 0.05 - 0.01 * i);
    std::vector<ConstraintRow> rows;
    std::vector<VecX> x(2);
    const std::vector<IslandBody*> bodies = {&flesh, &body};
    for (size_t b = 0; b < 2; ++b) bodies[b]->CalcPositions(kH, b == 0 ? v_flesh : v_rigid, x[b]);
    source.AppendIslandRows(IslandIterate(kH, bodies, {v_flesh, v_rigid}, x), rows);
    const long faces = std::count_if(rows.begin(), rows.end(), [](const ConstraintRow& row) {
      return row.friction_of == 0 && row.num_nodes == 3;
    });
    int checked = 0;
    const double worst = CheckRows(bodies, {v_flesh, v_rigid}, source, &checked);
    std::printf("face contact, %s: %ld face rows of %d normal rows, worst relative error %.2e\n",
                s == 0 ? "sphere" : "box", faces, checked, worst);
    EXPECT_GE(faces, 1);
    EXPECT_LT(worst, 1e-6);
  }
}

TEST(CouplingJacobianFdTest, AttachmentRowsMatchCentralDifferences) {
  std::unique_ptr<DeformableBody> cube = MakeCube(Vec3(-0.1, -0.1, 0.0), "sleeve");
  btSphereShape shape(0.05);
  btDefaultMotionState state(
      btTransform(btQuaternion(btVector3(0, 1, 2).normalized(), 0.7), btVector3(0.01, 0.02, 0.1)));
  btVector3 inertia;
  shape.calculateLocalInertia(1.0, inertia);
  btRigidBody rigid(1.0, &state, &shape, inertia);
  RigidIslandBody bone(&rigid);
  bone.BeginStep(kH);
  std::vector<int> nodes = {0, 3, 5};
  std::vector<Vec3> local;
  const btTransform inverse = rigid.getWorldTransform().inverse();
  for (int n : nodes)
    local.push_back(ToEigen(inverse * ToBullet(cube->node_position(n) + Vec3(0.01, 0, 0))));
  NodeAttachmentSource source(*cube, &bone, nodes, local, 2);
  DeformableIslandBody flesh(*cube);
  VecX v_bone(6);
  v_bone << -0.3, 0.2, 0.1, 0.0, 0.0, 0.0;
  int rows = 0;
  const double worst = CheckRows(
      {&flesh, &bone}, {VecX::Constant(3 * cube->num_nodes(), -0.1), v_bone}, source, &rows);
  std::printf("attachment: %d rows, worst relative error %.2e\n", rows, worst);
  EXPECT_EQ(rows, 9);
  EXPECT_LT(worst, 1e-6);
}

TEST(CouplingJacobianFdTest, VertexAgainstTriangleRowsMatchCentralDifferences) {
  // The upper cube's bottom corners sit 1 cm into the lower cube's top face, off its edges.
  std::unique_ptr<DeformableBody> lower = MakeCube(Vec3(0.0, 0.0, 0.0), "lower");
  std::unique_ptr<DeformableBody> upper = MakeCube(Vec3(0.03, 0.05, 0.19), "upper");
  const auto& lower_mesh = static_cast<const TetElementModel&>(lower->model()).mesh();
  const auto& upper_mesh = static_cast<const TetElementModel&>(upper->model()).mesh();
  DeformableContactSource source(*lower, MakeTetContactSurface(lower_mesh), *upper,
                                 MakeTetContactSurface(upper_mesh), 3, 0.5, 0.05);
  DeformableIslandBody a(*lower), b(*upper);
  VecX va = VecX::Zero(3 * lower->num_nodes()), vb = VecX::Zero(3 * upper->num_nodes());
  for (int i = 0; i < upper->num_nodes(); ++i) vb.segment<3>(3 * i) = Vec3(0.01 * i, -0.02, 0.03);
  int rows = 0;
  const double worst = CheckRows({&a, &b}, {va, vb}, source, &rows);
  std::printf("vertex vs triangle: %d normal rows, worst relative error %.2e\n", rows, worst);
  EXPECT_GT(rows, 0);
  EXPECT_LT(worst, 1e-6);
}

}  // namespace
}  // namespace taut
