#include "demos/render/image.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace taut::render {

Image::Image(int width_, int height_, const Vec3& colour)
    : width(width_), height(height_), rgb(static_cast<size_t>(width_) * height_ * 3) {
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) Set(x, y, colour);
}

void Image::Set(int x, int y, const Vec3& colour) {
  if (x < 0 || y < 0 || x >= width || y >= height) return;
  uint8_t* p = &rgb[(static_cast<size_t>(y) * width + x) * 3];
  for (int k = 0; k < 3; ++k)
    p[k] = static_cast<uint8_t>(std::lround(255.0 * std::clamp(colour[k], 0.0, 1.0)));
}

Vec3 Image::Get(int x, int y) const {
  const uint8_t* p = &rgb[(static_cast<size_t>(y) * width + x) * 3];
  return Vec3(p[0], p[1], p[2]) / 255.0;
}

Rasterizer::Rasterizer(Image& image)
    : image_(image),
      depth_(static_cast<size_t>(image.width) * image.height,
             std::numeric_limits<float>::infinity()),
      tags_(depth_.size(), -1) {}

void Rasterizer::DrawTriangle(const Vec3 p[3], const Vec3 colour[3]) {
  // Signed doubled area; both windings are filled (culling is the caller's choice).
  const double area =
      (p[1].x() - p[0].x()) * (p[2].y() - p[0].y()) - (p[2].x() - p[0].x()) * (p[1].y() - p[0].y());
  if (std::abs(area) < 1e-12 || !std::isfinite(area)) return;
  const double lo_x = std::min({p[0].x(), p[1].x(), p[2].x()});
  const double hi_x = std::max({p[0].x(), p[1].x(), p[2].x()});
  const double lo_y = std::min({p[0].y(), p[1].y(), p[2].y()});
  const double hi_y = std::max({p[0].y(), p[1].y(), p[2].y()});
  const int x0 = std::max(0, static_cast<int>(std::floor(lo_x)));
  const int x1 = std::min(image_.width - 1, static_cast<int>(std::ceil(hi_x)));
  const int y0 = std::max(0, static_cast<int>(std::floor(lo_y)));
  const int y1 = std::min(image_.height - 1, static_cast<int>(std::ceil(hi_y)));
  const double inv = 1.0 / area;
  for (int y = y0; y <= y1; ++y) {
    const double py = y + 0.5;
    for (int x = x0; x <= x1; ++x) {
      const double px = x + 0.5;
      // Barycentric weights of the pixel centre (edge functions over the signed area).
      const double w0 =
          ((p[1].x() - px) * (p[2].y() - py) - (p[2].x() - px) * (p[1].y() - py)) * inv;
      const double w1 =
          ((p[2].x() - px) * (p[0].y() - py) - (p[0].x() - px) * (p[2].y() - py)) * inv;
      const double w2 = 1.0 - w0 - w1;
      if (w0 < 0.0 || w1 < 0.0 || w2 < 0.0) continue;
      const float z = static_cast<float>(w0 * p[0].z() + w1 * p[1].z() + w2 * p[2].z());
      float& d = depth_[static_cast<size_t>(y) * image_.width + x];
      if (z >= d) continue;
      d = z;
      tags_[static_cast<size_t>(y) * image_.width + x] = tag_;
      image_.Set(x, y, w0 * colour[0] + w1 * colour[1] + w2 * colour[2]);
    }
  }
}

void Blit(const Image& tile, int x, int y, Image& image) {
  for (int ty = 0; ty < tile.height; ++ty) {
    const int iy = y + ty;
    if (iy < 0 || iy >= image.height) continue;
    for (int tx = 0; tx < tile.width; ++tx) {
      const int ix = x + tx;
      if (ix < 0 || ix >= image.width) continue;
      for (int k = 0; k < 3; ++k)
        image.rgb[(static_cast<size_t>(iy) * image.width + ix) * 3 + k] =
            tile.rgb[(static_cast<size_t>(ty) * tile.width + tx) * 3 + k];
    }
  }
}

}  // namespace taut::render
