// The one place where Bullet vectors convert to and from Eigen (internal math is double).
#pragma once

#include <LinearMath/btVector3.h>

#include "plugin/common.h"

namespace taut {

// btVector3 -> Eigen (widens to double in the float build).
inline Vec3 ToEigen(const btVector3& v) {
  return Vec3(static_cast<double>(v.x()), static_cast<double>(v.y()), static_cast<double>(v.z()));
}

// Eigen -> btVector3.
inline btVector3 ToBullet(const Vec3& v) {
  return btVector3(static_cast<btScalar>(v.x()), static_cast<btScalar>(v.y()),
                   static_cast<btScalar>(v.z()));
}

}  // namespace taut
