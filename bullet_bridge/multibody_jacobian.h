// Jacobians of points and frames on the links of a btMultiBody with respect to its generalized
// velocity qdot = [omega_base; v_base; joint rates] (Bullet's velocity vector, 6 + dofs entries;
// the base entries stay 0 for a fixed base).
#pragma once

#include <BulletDynamics/Featherstone/btMultiBody.h>

#include "plugin/common.h"

namespace taut {

// Scratch arrays Bullet's Jacobian routines take (kept to avoid allocation per call).
struct MultiBodyScratch {
  btAlignedObjectArray<btScalar> r;
  btAlignedObjectArray<btVector3> v;
  btAlignedObjectArray<btMatrix3x3> m;
};

// Number of generalized velocities Bullet stores for the body: 6 + getNumDofs().
int CountMultiBodyVelocities(const btMultiBody& body);

// j with d . (velocity of the material point of `link` at world point p) = j . qdot
// (btMultiBody::fillContactJacobianMultiDof; link -1 is the base). The body's cached kinematics
// (link rotations and offsets) must be those of its current joint positions.
VecX CalcMultiBodyPointJacobian(const btMultiBody& body, int link, const Vec3& p, const Vec3& d,
                                MultiBodyScratch& scratch);

// 6 x n Jacobian of `link`'s frame at world point p: rows 0-2 the angular velocity omega_link,
// rows 3-5 the velocity of the link's material point at p (btMultiBody::
// fillConstraintJacobianMultiDof with unit angular or linear directions).
Eigen::Matrix<double, 6, Eigen::Dynamic> CalcMultiBodyFrameJacobian(const btMultiBody& body,
                                                                    int link, const Vec3& p,
                                                                    MultiBodyScratch& scratch);

// The body's generalized velocity qdot (6 + dofs entries).
VecX GetMultiBodyVelocity(const btMultiBody& body);

}  // namespace taut
