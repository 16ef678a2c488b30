// The one place where Bullet vectors convert to and from Eigen (internal math is double).
#pragma once

#include <LinearMath/btMatrix3x3.h>
#include <LinearMath/btVector3.h>

#include "plugin/common.h"

namespace taut {

// btVector3 -> Eigen (widens to double in the float build).
inline Vec3 ToEigen(const btVector3& v) {
  return Vec3(static_cast<double>(v.x()), static_cast<double>(v.y()), static_cast<double>(v.z()));
}

// btMatrix3x3 -> Eigen (widens to double in the float build).
inline Mat3 ToEigen(const btMatrix3x3& m) {
  Mat3 out;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out(r, c) = static_cast<double>(m[r][c]);
  return out;
}

// Eigen -> btVector3.
inline btVector3 ToBullet(const Vec3& v) {
  return btVector3(static_cast<btScalar>(v.x()), static_cast<btScalar>(v.y()),
                   static_cast<btScalar>(v.z()));
}

}  // namespace taut
