#include "bullet_bridge/multibody_island_body.h"

#include <BulletDynamics/Featherstone/btMultiBodyLinkCollider.h>
#include <LinearMath/btTransformUtil.h>

#include <Eigen/Eigenvalues>

#include "bullet_bridge/eigen_bullet.h"

namespace taut {

namespace {
// Pseudo-inverse of a symmetric PSD matrix (zero-mobility directions -> 0).
MatX CalcSymmetricPseudoInverse(const MatX& m) {
  Eigen::SelfAdjointEigenSolver<MatX> eigen(m);
  const VecX& e = eigen.eigenvalues();
  const double largest = e.cwiseAbs().maxCoeff();
  VecX inv = VecX::Zero(e.size());
  for (int i = 0; i < e.size(); ++i)
    if (e[i] > 1e-12 * largest) inv[i] = 1.0 / e[i];
  return eigen.eigenvectors() * inv.asDiagonal() * eigen.eigenvectors().transpose();
}

// The collider of `link` (-1: the base), or null.
const btMultiBodyLinkCollider* FindCollider(const btMultiBody& body, int link) {
  return link < 0 ? body.getBaseCollider() : body.getLinkCollider(link);
}
}  // namespace

MultiBodyIslandBody::MultiBodyIslandBody(btMultiBody* body) : body_(body) {
  TAUT_DEMAND(body != nullptr, "MultiBodyIslandBody: multibody is null");
  FitSizes();
}

void MultiBodyIslandBody::FitSizes() {
  const int count = CountMultiBodyVelocities(*body_);
  if (count == num_velocities_) return;
  TAUT_DEMAND(count <= kMaxVelocities, "multibody with ", body_->getNumDofs(),
              " joint dofs: a deformable island takes at most ", kMaxVelocities - 6);
  num_velocities_ = count;
  num_blocks_ = (count + 2) / 3;
  const int n = 3 * num_blocks_;
  v_star_.setZero(n);
  v_.setZero(n);
  W_.setZero(n, n);
  M_.setZero(n, n);
  newton_added_.setZero(n, n);
}

void MultiBodyIslandBody::BeginStep(double /*h*/) {
  FitSizes();  // the world keeps an island body across steps; its multibody may have changed
  v_star_.setZero();
  v_star_.head(num_velocities_) = GetMultiBodyVelocity(*body_);
  v_ = v_star_;
  CalcMobility();
  M_ = CalcSymmetricPseudoInverse(W_);
  const int num_links = body_->getNumLinks();
  collider_start_.resize(num_links + 1);
  collider_jacobian_.resize(num_links + 1);
  for (int link = -1; link < num_links; ++link) {
    const btMultiBodyLinkCollider* collider = FindCollider(*body_, link);
    if (collider == nullptr) continue;
    collider_start_[link + 1] = collider->getWorldTransform();
    collider_jacobian_[link + 1] = CalcMultiBodyFrameJacobian(
        *body_, link, ToEigen(collider->getWorldTransform().getOrigin()), scratch_);
  }
}

void MultiBodyIslandBody::CalcMobility() {
  // Column k of W = M^-1 is the velocity change of a unit generalized impulse e_k (Featherstone's
  // articulated-body algorithm, Bullet's calcAccelerationDeltasMultiDof).
  const int n = num_velocities_;
  btAlignedObjectArray<btScalar> force, delta;
  force.resize(n, btScalar(0));
  delta.resize(n, btScalar(0));
  W_.setZero();
  const int first = body_->hasFixedBase() ? 6 : 0;
  for (int k = first; k < n; ++k) {
    force[k] = btScalar(1);
    body_->calcAccelerationDeltasMultiDof(&force[0], &delta[0], scratch_.r, scratch_.v);
    force[k] = btScalar(0);
    for (int r = first; r < n; ++r) W_(r, k) = static_cast<double>(delta[r]);
  }
  W_ = (0.5 * (W_ + W_.transpose())).eval();  // symmetric up to round-off
}

void MultiBodyIslandBody::EndStep() {
  const VecX delta = v_.head(num_velocities_) - GetMultiBodyVelocity(*body_);
  btAlignedObjectArray<btScalar> dv;
  dv.resize(num_velocities_, btScalar(0));
  for (int k = 0; k < num_velocities_; ++k) dv[k] = static_cast<btScalar>(delta[k]);
  body_->applyDeltaVeeMultiDof(&dv[0], btScalar(1));
}

void MultiBodyIslandBody::AbortStep() {
  v_ = v_star_;
  EndStep();
}

void MultiBodyIslandBody::FactorNewtonMatrix() {
  const int n = 3 * num_blocks_;
  newton_lu_.compute(MatX::Identity(n, n) + W_ * newton_added_);
}

void MultiBodyIslandBody::SolveNewton(Eigen::Ref<VecX> rhs) const {
  const VecX mobile = W_ * rhs;
  rhs = newton_lu_.solve(mobile);
}

void MultiBodyIslandBody::ApplyNewtonMatrix(const VecX& v, VecX& out) const {
  out = M_ * v + newton_added_ * v;
}

int MultiBodyIslandBody::FillPointRowEntries(int link, const Vec3& p, const Vec3& d, double sign,
                                             int* blocks, Vec3* J) const {
  VecX j = VecX::Zero(3 * num_blocks_);
  j.head(num_velocities_) = sign * CalcMultiBodyPointJacobian(*body_, link, p, d, scratch_);
  if (body_->hasFixedBase()) j.head<6>().setZero();  // Bullet fills them; they do not move
  int count = 0;
  for (int b = 0; b < num_blocks_; ++b) {
    const Vec3 entry = j.segment<3>(3 * b);
    if (entry.isZero(0.0)) continue;
    blocks[count] = b;
    J[count++] = entry;
  }
  return count;
}

btTransform MultiBodyIslandBody::PredictColliderTransform(int link, double h, const VecX& v) const {
  const auto& J = collider_jacobian_[link + 1];
  const Eigen::Matrix<double, 6, 1> twist = J * v.head(num_velocities_);
  btTransform predicted;
  btTransformUtil::integrateTransform(collider_start_[link + 1], ToBullet(Vec3(twist.tail<3>())),
                                      ToBullet(Vec3(twist.head<3>())), static_cast<btScalar>(h),
                                      predicted);
  return predicted;
}

}  // namespace taut
