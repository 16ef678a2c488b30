#include "demos/render/text.h"

#include <stb_easy_font.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace taut::render {

namespace {
// stb_easy_font's vertex: x, y, z and an RGBA colour; four per quad.
struct FontVertex {
  float x, y, z;
  unsigned char colour[4];
};

// The quads of `text` at unit scale, origin at the top left.
std::vector<FontVertex> MakeQuads(const std::string& text) {
  std::vector<FontVertex> quads(text.size() * 300 / sizeof(FontVertex) * 4 + 64);
  std::string copy = text;
  const int n = stb_easy_font_print(0.0f, 0.0f, copy.data(), nullptr, quads.data(),
                                    static_cast<int>(quads.size() * sizeof(FontVertex)));
  quads.resize(static_cast<size_t>(n) * 4);
  return quads;
}

// Fills the axis-aligned quads scaled by `scale` and grown by `grow` pixels, offset to (x, y).
void FillQuads(Image& image, const std::vector<FontVertex>& quads, int x, int y, int scale,
               int grow, const Vec3& colour) {
  for (size_t q = 0; q + 3 < quads.size(); q += 4) {
    float lo_x = quads[q].x, hi_x = quads[q].x, lo_y = quads[q].y, hi_y = quads[q].y;
    for (size_t k = 1; k < 4; ++k) {
      lo_x = std::min(lo_x, quads[q + k].x);
      hi_x = std::max(hi_x, quads[q + k].x);
      lo_y = std::min(lo_y, quads[q + k].y);
      hi_y = std::max(hi_y, quads[q + k].y);
    }
    const int x0 = x + static_cast<int>(std::lround(lo_x * scale)) - grow;
    const int x1 = x + static_cast<int>(std::lround(hi_x * scale)) + grow;
    const int y0 = y + static_cast<int>(std::lround(lo_y * scale)) - grow;
    const int y1 = y + static_cast<int>(std::lround(hi_y * scale)) + grow;
    for (int py = y0; py < y1; ++py)
      for (int px = x0; px < x1; ++px) image.Set(px, py, colour);
  }
}
}  // namespace

int CalcTextWidth(const std::string& text, int scale) {
  std::string copy = text;
  return stb_easy_font_width(copy.data()) * scale;
}

int CalcTextHeight(const std::string& text, int scale) {
  std::string copy = text;
  return stb_easy_font_height(copy.data()) * scale;
}

void DrawText(Image& image, int x, int y, const std::string& text, int scale, const Vec3& colour,
              const Vec3& halo) {
  const std::vector<FontVertex> quads = MakeQuads(text);
  if (halo.minCoeff() >= 0.0) FillQuads(image, quads, x, y, scale, std::max(1, scale / 2), halo);
  FillQuads(image, quads, x, y, scale, 0, colour);
}

}  // namespace taut::render
