// Orthographic camera of the pictures: a view basis from a direction, fitted to what it shows.
#pragma once

#include <cmath>

#include "plugin/common.h"

namespace taut::render {

// Orthographic projection onto a width x height image, z up in the world appearing up in the
// image. Fit it by feeding every point it must show to Include(), then Fit().
class Camera {
 public:
  // `direction` points from the scene towards the eye (need not be unit, must not be parallel to
  // z exactly: then x is taken as the image right).
  explicit Camera(const Vec3& direction);
  // Widens the region to show by point p [m].
  void Include(const Vec3& p);
  // Scales and centres the region shown so it fills the image with `margin` pixels on each side
  // and `top` pixels above (room for the caption and labels).
  void Fit(int width, int height, int margin, int top);
  // Pixel coordinates (x right, y down, pixel centres at integers + 0.5) and depth (larger:
  // farther from the eye) of world point p.
  Vec3 Project(const Vec3& p) const;
  // Unit vector from the scene towards the eye.
  const Vec3& eye_direction() const { return forward_; }
  // Pixels per metre after Fit().
  double scale() const { return scale_; }
  bool empty() const { return !(lo_.x() <= hi_.x()); }

 private:
  Vec3 right_, up_, forward_;
  Vec3 lo_ = Vec3::Constant(HUGE_VAL), hi_ = Vec3::Constant(-HUGE_VAL);  // view-space bounds
  double scale_ = 1.0;
  double offset_x_ = 0.0, offset_y_ = 0.0;  // pixel position of view-space (0, 0)
};

}  // namespace taut::render
