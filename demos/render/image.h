// An 8-bit RGB image and a depth-buffered triangle rasterizer drawing into it.
#pragma once

#include <cstdint>
#include <vector>

#include "plugin/common.h"

namespace taut::render {

// Row-major 8-bit RGB pixels, row 0 at the top.
struct Image {
  Image(int width, int height, const Vec3& colour = Vec3::Ones());
  int width, height;
  std::vector<uint8_t> rgb;  // (height x width x 3)
  // Sets pixel (x, y) to colour (components in [0, 1], clamped); ignores pixels outside.
  void Set(int x, int y, const Vec3& colour);
  Vec3 Get(int x, int y) const;
};

// Fills triangles into an image, nearest depth wins (one depth per pixel, pixel centres sampled).
class Rasterizer {
 public:
  explicit Rasterizer(Image& image);
  // p: pixel x, pixel y, depth (larger: farther) per corner; colours per corner, interpolated.
  void DrawTriangle(const Vec3 p[3], const Vec3 colour[3]);
  // Depth at pixel (x, y); +inf where nothing was drawn.
  float depth(int x, int y) const { return depth_[static_cast<size_t>(y) * image_.width + x]; }
  // Tag stored with every pixel drawn from now on (e.g. a body index; -1 at the start).
  void set_tag(int tag) { tag_ = tag; }
  // Tag of the nearest triangle drawn at pixel (x, y), -1 where none was.
  int tag(int x, int y) const { return tags_[static_cast<size_t>(y) * image_.width + x]; }

 private:
  Image& image_;
  std::vector<float> depth_;
  std::vector<int> tags_;
  int tag_ = -1;
};

// Copies `tile` into `image` with its top-left corner at (x, y) (clipped).
void Blit(const Image& tile, int x, int y, Image& image);

}  // namespace taut::render
