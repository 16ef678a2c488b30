#include "bullet_bridge/rigid_island_body.h"

#include <LinearMath/btTransformUtil.h>

#include <Eigen/Eigenvalues>

#include "bullet_bridge/eigen_bullet.h"

namespace taut {

namespace {
// Pseudo-inverse of a symmetric PSD 3x3 matrix (infinite inertia about locked axes -> 0).
Mat3 CalcSymmetricPseudoInverse(const Mat3& m) {
  Eigen::SelfAdjointEigenSolver<Mat3> eigen(m);
  const Vec3& e = eigen.eigenvalues();
  Vec3 inv = Vec3::Zero();
  for (int i = 0; i < 3; ++i)
    if (e[i] > 1e-12 * e.cwiseAbs().maxCoeff()) inv[i] = 1.0 / e[i];
  return eigen.eigenvectors() * inv.asDiagonal() * eigen.eigenvectors().transpose();
}

}  // namespace

RigidIslandBody::RigidIslandBody(btRigidBody* body) : body_(body) {
  TAUT_DEMAND(body != nullptr, "RigidIslandBody: body is null");
  v_star_.setZero(6);
  v_.setZero(6);
}

void RigidIslandBody::BeginStep(double h) {
  start_ = body_->getWorldTransform();
  start_linear_ = body_->getLinearVelocity();
  start_angular_ = body_->getAngularVelocity();
  inverse_inertia_ = ToEigen(body_->getInvInertiaTensorWorld());
  inertia_ = CalcSymmetricPseudoInverse(inverse_inertia_);
  // Bullet's solver integrates external forces inside the solve (btSequentialImpulseConstraint-
  // Solver::initSolverBody); v* reproduces that impulse for a body taut solves instead.
  const btScalar step = static_cast<btScalar>(h);
  btVector3 angular_impulse = body_->getTotalTorque() * body_->getInvInertiaTensorWorld() * step;
  if (body_->getFlags() & BT_ENABLE_GYROSCOPIC_FORCE_IMPLICIT_BODY)
    angular_impulse += body_->computeGyroscopicImpulseImplicit_Body(step);
  const btVector3 lin =
      body_->getLinearVelocity() + body_->getTotalForce() * body_->getInvMass() * step;
  const btVector3 ang = body_->getAngularVelocity() + angular_impulse;
  v_star_ << ToEigen(lin), ToEigen(ang);
  v_ = v_star_;
}

void RigidIslandBody::EndStep() {
  body_->setWorldTransform(start_);
  body_->setLinearVelocity(ToBullet(Vec3(v_.head<3>())));
  body_->setAngularVelocity(ToBullet(Vec3(v_.tail<3>())));
}

void RigidIslandBody::AbortStep() {
  body_->setWorldTransform(start_);
  body_->setLinearVelocity(start_linear_);
  body_->setAngularVelocity(start_angular_);
}

void RigidIslandBody::SolveSystemColumns(Eigen::Ref<MatX> columns) const {
  const Vec3 lin_factor = ToEigen(body_->getLinearFactor()) * body_->getInvMass();
  const Vec3 ang_factor = ToEigen(body_->getAngularFactor());
  for (int c = 0; c < columns.cols(); ++c) {
    columns.col(c).head<3>() = lin_factor.cwiseProduct(columns.col(c).head<3>());
    const Vec3 torque = ang_factor.cwiseProduct(columns.col(c).tail<3>());
    columns.col(c).tail<3>() = ang_factor.cwiseProduct(inverse_inertia_ * torque);
  }
}

void RigidIslandBody::ApplySystemMatrix(const VecX& v, VecX& out) const {
  const double inv_mass = body_->getInvMass();
  out.resize(6);
  out.head<3>() = (inv_mass > 0.0 ? 1.0 / inv_mass : 0.0) * v.head<3>();
  out.tail<3>() = inertia_ * v.tail<3>();
}

double RigidIslandBody::CalcBlockMobility(int i, const Vec3& J) const {
  // J^T A^+ J of one block, as SolveSystemColumns applies A^+ (axis factors included).
  if (i == 0)
    return J.dot((ToEigen(body_->getLinearFactor()) * body_->getInvMass()).cwiseProduct(J));
  const Vec3 torque = ToEigen(body_->getAngularFactor()).cwiseProduct(J);
  return torque.dot(inverse_inertia_ * torque);
}

void RigidIslandBody::FactorNewtonMatrix() {
  mobility_.setIdentity();
  SolveSystemColumns(mobility_);
  newton_lu_.compute(Eigen::Matrix<double, 6, 6>::Identity() + mobility_ * newton_added_);
}

void RigidIslandBody::SolveNewton(Eigen::Ref<VecX> rhs) const {
  const Eigen::Matrix<double, 6, 1> mobile = mobility_ * rhs.head<6>();
  rhs.head<6>() = newton_lu_.solve(mobile);
}

void RigidIslandBody::ApplyNewtonMatrix(const VecX& v, VecX& out) const {
  ApplySystemMatrix(v, out);
  out += newton_added_ * v.head<6>();
}

btTransform RigidIslandBody::PredictTransform(double h, const VecX& v) const {
  btTransform predicted;
  btTransformUtil::integrateTransform(start_, ToBullet(Vec3(v.head<3>())),
                                      ToBullet(Vec3(v.tail<3>())), static_cast<btScalar>(h),
                                      predicted);
  return predicted;
}

Vec3 RigidIslandBody::CalcPointVelocity(const VecX& v, const Vec3& p, const Vec3& com) {
  return v.head<3>() + Vec3(v.tail<3>()).cross(p - com);
}

}  // namespace taut
