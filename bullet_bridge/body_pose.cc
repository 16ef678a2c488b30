#include "bullet_bridge/body_pose.h"

#include <string>

#include "bullet_bridge/eigen_bullet.h"

namespace taut {
namespace {

// Throws InputError naming `where` unless pose is finite and its basis a rotation.
void CheckRigidPose(const btTransform& pose, const std::string& where) {
  const Mat3 R = ToEigen(pose.getBasis());
  TAUT_DEMAND(R.allFinite() && ToEigen(pose.getOrigin()).allFinite(), where,
              ": pose is not finite");
  const double error = (R.transpose() * R - Mat3::Identity()).cwiseAbs().maxCoeff();
  TAUT_DEMAND(error <= 1e-5 && R.determinant() > 0.0, where,
              ": pose basis must be a rotation (orthonormal, det +1), got max |R^T R - I| = ",
              error, ", det R = ", R.determinant());
}

}  // namespace

void PlaceAtPose(DeformableBody& body, const btTransform& pose) {
  CheckRigidPose(pose, "body '" + body.name() + "'");
  const Mat3 R = ToEigen(pose.getBasis());
  const Vec3 t = ToEigen(pose.getOrigin());
  const VecX& rest = body.model().rest_positions();
  VecX x(rest.size());
  for (int i = 0; i < body.num_nodes(); ++i) x.segment<3>(3 * i) = R * rest.segment<3>(3 * i) + t;
  body.set_x(x);
}

}  // namespace taut
