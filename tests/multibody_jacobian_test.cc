// The multibody side of a deformable island: the contact Jacobian of a point on a link against
// central differences of the point's motion (d . dp/dt = j . qdot), its split into row blocks, and
// the island body's mobility W = M^-1 (symmetric, the inverse of A = M on the moving dofs).
#include "bullet_bridge/multibody_jacobian.h"

#include <BulletDynamics/Featherstone/btMultiBody.h>
#include <gtest/gtest.h>

#include <memory>

#include "bullet_bridge/eigen_bullet.h"
#include "bullet_bridge/multibody_island_body.h"

namespace taut {
namespace {

// A floating (or fixed) base with a chain: revolute about z, prismatic along x, revolute about y.
std::unique_ptr<btMultiBody> MakeChain(bool fixed_base) {
  auto body =
      std::make_unique<btMultiBody>(3, btScalar(2), btVector3(0.1, 0.2, 0.3), fixed_base, false);
  const btQuaternion identity = btQuaternion::getIdentity();
  body->setupRevolute(0, 1.0, btVector3(0.02, 0.03, 0.04), -1, identity, btVector3(0, 0, 1),
                      btVector3(0.1, 0.0, 0.2), btVector3(0.15, 0.0, 0.0), true);
  body->setupPrismatic(1, 0.5, btVector3(0.01, 0.01, 0.01), 0, identity, btVector3(1, 0, 0),
                       btVector3(0.15, 0.05, 0.0), btVector3(0.1, 0.0, 0.0), true);
  body->setupRevolute(2, 0.3, btVector3(0.005, 0.006, 0.007), 1, identity, btVector3(0, 1, 0),
                      btVector3(0.1, 0.0, 0.0), btVector3(0.0, 0.0, -0.2), true);
  body->finalizeMultiDof();
  body->setBasePos(btVector3(0.3, -0.2, 1.0));
  body->setWorldToBaseRot(btQuaternion(btVector3(1, 2, 3).normalized(), 0.7));
  const btScalar q[3] = {0.4, 0.05, -0.6};
  for (int l = 0; l < 3; ++l) body->setJointPos(l, q[l]);
  const btScalar qdot[3] = {0.8, -0.3, 1.1};
  for (int l = 0; l < 3; ++l) body->setJointVel(l, qdot[l]);
  if (!fixed_base) {
    body->setBaseVel(btVector3(0.2, -0.4, 0.1));
    body->setBaseOmega(btVector3(-0.5, 0.3, 0.7));
  }
  btAlignedObjectArray<btQuaternion> world_to_local;
  btAlignedObjectArray<btVector3> local_origin;
  body->forwardKinematics(world_to_local, local_origin);
  return body;
}

// World position of the material point `local` of `link` after moving the body's positions by
// its velocity for time t (Bullet's own integrator), then restoring them.
Vec3 CalcMovedPoint(btMultiBody& body, int link, const btVector3& local, double t) {
  const int n = body.getNumPosVars() + 7;
  btAlignedObjectArray<btScalar> q0;
  q0.resize(n);
  // Save: base pose and joint positions.
  const btVector3 base_pos = body.getBasePos();
  const btQuaternion base_rot = body.getWorldToBaseRot();
  std::vector<btScalar> joints;
  for (int l = 0; l < body.getNumLinks(); ++l) joints.push_back(body.getJointPos(l));
  body.stepPositionsMultiDof(static_cast<btScalar>(t));
  const Vec3 p = ToEigen(body.localPosToWorld(link, local));
  body.setBasePos(base_pos);
  body.setWorldToBaseRot(base_rot);
  for (int l = 0; l < body.getNumLinks(); ++l) body.setJointPos(l, joints[l]);
  return p;
}

// d . (central difference of the point's motion) against j . qdot, for every link and the base.
void CheckPointJacobian(bool fixed_base) {
  std::unique_ptr<btMultiBody> body = MakeChain(fixed_base);
  MultiBodyScratch scratch;
  const VecX qdot = GetMultiBodyVelocity(*body);
  const Vec3 d = Vec3(0.3, -0.8, 0.5).normalized();
  const double t = 1e-6;
  for (int link = -1; link < body->getNumLinks(); ++link) {
    const btVector3 local(0.05, -0.03, 0.07);
    const Vec3 p = ToEigen(body->localPosToWorld(link, local));
    const VecX j = CalcMultiBodyPointJacobian(*body, link, p, d, scratch);
    ASSERT_EQ(j.size(), 6 + body->getNumDofs());
    const Vec3 forward = CalcMovedPoint(*body, link, local, t);
    const Vec3 backward = CalcMovedPoint(*body, link, local, -t);
    const double fd = d.dot(forward - backward) / (2.0 * t);
    const double jv = j.dot(qdot);
    EXPECT_NEAR(jv, fd, 1e-6 * std::max(1.0, std::abs(fd)))
        << "link " << link << (fixed_base ? " (fixed base)" : " (floating base)");
    if (!fixed_base || link >= 0) EXPECT_GT(std::abs(jv), 1e-3) << "link " << link << " moves";
  }
}

TEST(MultiBodyJacobian, PointJacobianMatchesFiniteDifferencesFloatingBase) {
  CheckPointJacobian(false);
}

TEST(MultiBodyJacobian, PointJacobianMatchesFiniteDifferencesFixedBase) {
  CheckPointJacobian(true);
}

// The island body's rows hold the same Jacobian, in 3-vector blocks of qdot (zero blocks left
// out): for the fixed base the base blocks 0 and 1 are all zero.
TEST(MultiBodyJacobian, RowEntriesAreTheJacobianInBlocks) {
  for (bool fixed_base : {false, true}) {
    std::unique_ptr<btMultiBody> body = MakeChain(fixed_base);
    MultiBodyIslandBody island(body.get());
    ASSERT_EQ(island.num_blocks(), 3);  // 6 + 3 velocities
    MultiBodyScratch scratch;
    const Vec3 p = ToEigen(body->localPosToWorld(2, btVector3(0.01, 0.02, 0.03)));
    const Vec3 d = Vec3(0.0, 0.6, 0.8);
    VecX j = CalcMultiBodyPointJacobian(*body, 2, p, d, scratch);
    if (fixed_base) j.head<6>().setZero();  // Bullet fills them; they never move
    int blocks[kMaxRowNodes];
    Vec3 J[kMaxRowNodes];
    const int count = island.FillPointRowEntries(2, p, d, -1.0, blocks, J);
    VecX assembled = VecX::Zero(9);
    for (int k = 0; k < count; ++k) assembled.segment<3>(3 * blocks[k]) = J[k];
    EXPECT_TRUE(assembled.isApprox(-j, 1e-14));
    EXPECT_EQ(count, fixed_base ? 1 : 3);
  }
}

// W from unit impulses (Bullet's articulated-body algorithm) is symmetric and M = W^+ inverts it
// on the moving dofs; the kinetic energy qdot^T M qdot / 2 is the sum over bodies of
// m v_com^2 / 2 + omega^T I omega / 2.
TEST(MultiBodyJacobian, MobilityIsTheInverseMassMatrix) {
  std::unique_ptr<btMultiBody> body = MakeChain(false);
  btAlignedObjectArray<btScalar> scratch_r;
  btAlignedObjectArray<btVector3> scratch_v;
  btAlignedObjectArray<btMatrix3x3> scratch_m;
  // Bullet's articulated-body pass (dt = 0: velocities unchanged) caches what W needs.
  body->computeAccelerationsArticulatedBodyAlgorithmMultiDof(0, scratch_r, scratch_v, scratch_m,
                                                             false, false, false);
  MultiBodyIslandBody island(body.get());
  island.BeginStep(0.01);
  MatX W = MatX::Identity(9, 9);
  island.SolveSystemColumns(W);
  EXPECT_TRUE(W.isApprox(W.transpose(), 1e-10));
  VecX Mv;
  const VecX qdot = island.v_star();
  island.ApplySystemMatrix(qdot, Mv);
  VecX back = qdot;
  MatX col = Mv;
  island.SolveSystemColumns(col);
  EXPECT_TRUE(col.col(0).isApprox(qdot, 1e-9));
  // Kinetic energy from the links' frame Jacobians at their centres of mass.
  MultiBodyScratch scratch;
  double energy = 0.0;
  for (int link = -1; link < body->getNumLinks(); ++link) {
    const double mass = link < 0 ? body->getBaseMass() : body->getLinkMass(link);
    const Vec3 inertia = ToEigen(link < 0 ? body->getBaseInertia() : body->getLinkInertia(link));
    const btQuaternion world_to_local =
        link < 0 ? body->getWorldToBaseRot()
                 : body->getLink(link).m_cachedWorldTransform.getRotation().inverse();
    const Vec3 com = ToEigen(body->localPosToWorld(link, btVector3(0, 0, 0)));
    const auto J = CalcMultiBodyFrameJacobian(*body, link, com, scratch);
    const Eigen::Matrix<double, 6, 1> twist = J * qdot.head(9);
    const Vec3 omega_local = ToEigen(quatRotate(world_to_local, ToBullet(Vec3(twist.head<3>()))));
    energy += 0.5 * mass * twist.tail<3>().squaredNorm() +
              0.5 * omega_local.dot(inertia.cwiseProduct(omega_local));
  }
  EXPECT_NEAR(0.5 * qdot.dot(Mv), energy, 1e-9 * energy);
}

}  // namespace
}  // namespace taut
