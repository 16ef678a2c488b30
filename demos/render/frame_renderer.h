// Draws one snapshot of a scene: lit surfaces over a checkered ground with shadows, a label per
// body and a caption.
#pragma once

#include <optional>
#include <string>

#include "demos/render/camera.h"
#include "demos/render/image.h"
#include "demos/render/scene_surfaces.h"

namespace taut::render {

// A checkered ground rectangle z = height over [lo, hi] in x and y, tiles of `tile` metres.
struct Ground {
  double z = 0.0;
  Eigen::Vector2d lo = Eigen::Vector2d::Zero(), hi = Eigen::Vector2d::Ones();
  double tile = 0.25;
};

// Look of a frame.
struct FrameStyle {
  int width = 640, height = 360;
  int text_scale = 2;  // pixel size of a font unit
  bool labels = true;  // a label above every body that has one
  Vec3 background = Vec3(1.0, 1.0, 1.0);
};

// The meshes seen by `camera` (already fitted to style.width x style.height), with `ground`
// when given and `caption` at the top left when non-empty.
Image RenderFrame(const std::vector<RenderMesh>& meshes, const Camera& camera,
                  const std::optional<Ground>& ground, const std::string& caption,
                  const FrameStyle& style);

}  // namespace taut::render
