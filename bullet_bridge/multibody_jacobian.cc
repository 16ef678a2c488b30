#include "bullet_bridge/multibody_jacobian.h"

#include "bullet_bridge/eigen_bullet.h"

namespace taut {

namespace {
// Bullet's generalized-force-sized row for one constraint direction (angular and linear parts).
VecX FillConstraintJacobian(const btMultiBody& body, int link, const Vec3& p, const Vec3& d_ang,
                            const Vec3& d_lin, MultiBodyScratch& scratch) {
  const int n = CountMultiBodyVelocities(body);
  btAlignedObjectArray<btScalar> jac;
  jac.resize(n, btScalar(0));
  body.fillConstraintJacobianMultiDof(link, ToBullet(p), ToBullet(d_ang), ToBullet(d_lin), &jac[0],
                                      scratch.r, scratch.v, scratch.m);
  VecX j(n);
  for (int k = 0; k < n; ++k) j[k] = static_cast<double>(jac[k]);
  return j;
}
}  // namespace

int CountMultiBodyVelocities(const btMultiBody& body) { return 6 + body.getNumDofs(); }

VecX CalcMultiBodyPointJacobian(const btMultiBody& body, int link, const Vec3& p, const Vec3& d,
                                MultiBodyScratch& scratch) {
  TAUT_DEMAND(link >= -1 && link < body.getNumLinks(), "multibody point Jacobian: link ", link,
              " out of range [-1, ", body.getNumLinks(), ")");
  return FillConstraintJacobian(body, link, p, Vec3::Zero(), d, scratch);
}

Eigen::Matrix<double, 6, Eigen::Dynamic> CalcMultiBodyFrameJacobian(const btMultiBody& body,
                                                                    int link, const Vec3& p,
                                                                    MultiBodyScratch& scratch) {
  TAUT_DEMAND(link >= -1 && link < body.getNumLinks(), "multibody frame Jacobian: link ", link,
              " out of range [-1, ", body.getNumLinks(), ")");
  Eigen::Matrix<double, 6, Eigen::Dynamic> J(6, CountMultiBodyVelocities(body));
  for (int k = 0; k < 3; ++k) {
    const Vec3 e = Vec3::Unit(k);
    J.row(k) = FillConstraintJacobian(body, link, p, e, Vec3::Zero(), scratch).transpose();
    J.row(3 + k) = FillConstraintJacobian(body, link, p, Vec3::Zero(), e, scratch).transpose();
  }
  return J;
}

VecX GetMultiBodyVelocity(const btMultiBody& body) {
  const int n = CountMultiBodyVelocities(body);
  const btScalar* qdot = body.getVelocityVector();
  VecX v(n);
  for (int k = 0; k < n; ++k) v[k] = static_cast<double>(qdot[k]);
  return v;
}

}  // namespace taut
