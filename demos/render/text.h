// Captions and labels in the pictures: ASCII text drawn with stb_easy_font's segment font.
#pragma once

#include <string>

#include "demos/render/image.h"

namespace taut::render {

// Width and height in pixels of `text` drawn at `scale` (integer pixel size of a font unit).
int CalcTextWidth(const std::string& text, int scale);
int CalcTextHeight(const std::string& text, int scale);
// Draws text with its top-left corner at (x, y) in `colour`, over a `halo` of one font unit
// (pass a negative component to draw no halo) so it stays legible on any background.
void DrawText(Image& image, int x, int y, const std::string& text, int scale, const Vec3& colour,
              const Vec3& halo = Vec3(1.0, 1.0, 1.0));

}  // namespace taut::render
