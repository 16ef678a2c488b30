#include "demos/render/camera.h"

#include <algorithm>
#include <cmath>

namespace taut::render {

Camera::Camera(const Vec3& direction) {
  forward_ = direction.normalized();
  right_ = Vec3::UnitZ().cross(forward_);
  if (right_.norm() < 1e-9) right_ = Vec3::UnitX();
  right_.normalize();
  up_ = forward_.cross(right_);
}

void Camera::Include(const Vec3& p) {
  const Vec3 v(right_.dot(p), up_.dot(p), forward_.dot(p));
  lo_ = lo_.cwiseMin(v);
  hi_ = hi_.cwiseMax(v);
}

void Camera::Fit(int width, int height, int margin, int top) {
  if (empty()) {
    lo_.setConstant(-1.0);
    hi_.setConstant(1.0);
  }
  const double w = std::max(hi_.x() - lo_.x(), 1e-9), h = std::max(hi_.y() - lo_.y(), 1e-9);
  const double usable_w = std::max(1, width - 2 * margin);
  const double usable_h = std::max(1, height - margin - top);
  scale_ = std::min(usable_w / w, usable_h / h);
  // Centre of the region at the centre of the usable part; y grows downwards in the image.
  offset_x_ = 0.5 * width - scale_ * 0.5 * (lo_.x() + hi_.x());
  offset_y_ = top + 0.5 * usable_h + scale_ * 0.5 * (lo_.y() + hi_.y());
}

Vec3 Camera::Project(const Vec3& p) const {
  return Vec3(offset_x_ + scale_ * right_.dot(p), offset_y_ - scale_ * up_.dot(p),
              -forward_.dot(p));
}

}  // namespace taut::render
