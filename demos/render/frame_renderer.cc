#include "demos/render/frame_renderer.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "demos/render/text.h"

namespace taut::render {

namespace {
constexpr double kAmbient = 0.38;
const Vec3 kGroundLight(0.90, 0.90, 0.88), kGroundDark(0.80, 0.80, 0.78);
const Vec3 kShadow(0.62, 0.62, 0.60);
const Vec3 kText(0.12, 0.12, 0.12);
constexpr int kCaptionX = 6, kCaptionY = 6;  // top-left corner of the caption [pixels]

// Brightness of a surface with unit normal n, turned towards the eye (two-sided lighting).
double CalcLight(Vec3 n, const Vec3& eye, const Vec3& light) {
  if (n.dot(eye) < 0.0) n = -n;
  return kAmbient + (1.0 - kAmbient) * std::max(0.0, n.dot(light));
}

// Unit normal of a triangle (zero when degenerate).
Vec3 CalcFaceNormal(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 n = (b - a).cross(c - a);
  const double length = n.norm();
  return length > 0.0 ? Vec3(n / length) : Vec3::Zero();
}

void DrawGround(const Ground& ground, const Camera& camera, Rasterizer& raster) {
  const int nx = std::clamp(
      static_cast<int>(std::ceil((ground.hi.x() - ground.lo.x()) / ground.tile)), 1, 400);
  const int ny = std::clamp(
      static_cast<int>(std::ceil((ground.hi.y() - ground.lo.y()) / ground.tile)), 1, 400);
  for (int i = 0; i < nx; ++i) {
    for (int j = 0; j < ny; ++j) {
      const double x0 = ground.lo.x() + i * ground.tile, y0 = ground.lo.y() + j * ground.tile;
      const double x1 = std::min(x0 + ground.tile, ground.hi.x());
      const double y1 = std::min(y0 + ground.tile, ground.hi.y());
      const Vec3 c = ((i + j) % 2 == 0) ? kGroundLight : kGroundDark;
      const Vec3 colours[3] = {c, c, c};
      const Vec3 a = camera.Project(Vec3(x0, y0, ground.z)),
                 b = camera.Project(Vec3(x1, y0, ground.z));
      const Vec3 d = camera.Project(Vec3(x1, y1, ground.z)),
                 e = camera.Project(Vec3(x0, y1, ground.z));
      const Vec3 t0[3] = {a, b, d}, t1[3] = {a, d, e};
      raster.DrawTriangle(t0, colours);
      raster.DrawTriangle(t1, colours);
    }
  }
}

// Vertical shadows of the meshes on the ground, drawn a little in front of it.
void DrawShadows(const std::vector<RenderMesh>& meshes, const Ground& ground, const Camera& camera,
                 Rasterizer& raster) {
  const Vec3 colours[3] = {kShadow, kShadow, kShadow};
  const double lift = 2.0 / camera.scale();  // two pixels' worth of depth towards the eye
  for (const RenderMesh& mesh : meshes) {
    for (const Triangle& t : mesh.triangles) {
      Vec3 p[3];
      for (int k = 0; k < 3; ++k) {
        const Vec3& v = mesh.vertices[t[k]];
        p[k] = camera.Project(Vec3(v.x(), v.y(), ground.z));
        p[k].z() -= lift;
      }
      raster.DrawTriangle(p, colours);
    }
  }
}

void DrawMesh(const RenderMesh& mesh, const Camera& camera, const Vec3& light, Rasterizer& raster) {
  const Vec3& eye = camera.eye_direction();
  std::vector<Vec3> projected(mesh.vertices.size());
  for (size_t i = 0; i < mesh.vertices.size(); ++i) projected[i] = camera.Project(mesh.vertices[i]);
  std::vector<Vec3> vertex_colour;
  if (mesh.smooth) {
    // Area-weighted vertex normals.
    std::vector<Vec3> normals(mesh.vertices.size(), Vec3::Zero());
    for (const Triangle& t : mesh.triangles) {
      const Vec3 n = (mesh.vertices[t[1]] - mesh.vertices[t[0]])
                         .cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
      for (int k = 0; k < 3; ++k) normals[t[k]] += n;
    }
    vertex_colour.resize(mesh.vertices.size());
    for (size_t i = 0; i < normals.size(); ++i) {
      const double length = normals[i].norm();
      const Vec3 n = length > 0.0 ? Vec3(normals[i] / length) : eye;
      vertex_colour[i] = CalcLight(n, eye, light) * mesh.colour;
    }
  }
  for (const Triangle& t : mesh.triangles) {
    const Vec3 p[3] = {projected[t[0]], projected[t[1]], projected[t[2]]};
    if (mesh.smooth) {
      const Vec3 c[3] = {vertex_colour[t[0]], vertex_colour[t[1]], vertex_colour[t[2]]};
      raster.DrawTriangle(p, c);
    } else {
      const Vec3 n = CalcFaceNormal(mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]]);
      const Vec3 c = CalcLight(n, eye, light) * mesh.colour;
      const Vec3 colours[3] = {c, c, c};
      raster.DrawTriangle(p, colours);
    }
  }
}

// A pixel rectangle [x0, x1) x [y0, y1).
struct Box {
  int x0, y0, x1, y1;
  bool Overlaps(const Box& o) const { return x0 < o.x1 && o.x0 < x1 && y0 < o.y1 && o.y0 < y1; }
};

// Labels next to their bodies, placed greedily: above the body, else to its right or left at
// mid-height, else higher above or below, whichever first covers no body pixel (tags >= 0 in the
// rasterizer) and no placed label.
void DrawLabels(const std::vector<RenderMesh>& meshes, const Camera& camera,
                const FrameStyle& style, const std::string& caption, const Rasterizer& raster,
                Image& image) {
  const int scale = std::max(1, style.text_scale - (style.width < 480 ? 1 : 0));
  std::vector<Box> bodies;
  std::vector<int> top_x;  // image x of each body's highest point: labels above it
  for (const RenderMesh& mesh : meshes) {
    double lo_x = HUGE_VAL, hi_x = -HUGE_VAL, lo_y = HUGE_VAL, hi_y = -HUGE_VAL, x_at_top = 0.0;
    for (const Vec3& v : mesh.vertices) {
      const Vec3 p = camera.Project(v);
      if (p.y() < lo_y) x_at_top = p.x();
      lo_x = std::min(lo_x, p.x());
      hi_x = std::max(hi_x, p.x());
      lo_y = std::min(lo_y, p.y());
      hi_y = std::max(hi_y, p.y());
    }
    bodies.push_back(mesh.vertices.empty() ? Box{0, 0, 0, 0}
                                           : Box{static_cast<int>(lo_x), static_cast<int>(lo_y),
                                                 static_cast<int>(hi_x), static_cast<int>(hi_y)});
    top_x.push_back(static_cast<int>(x_at_top));
  }
  std::vector<Box> placed;
  if (!caption.empty())
    placed.push_back({0, 0, kCaptionX + CalcTextWidth(caption, style.text_scale) + 4,
                      kCaptionY + CalcTextHeight(caption, style.text_scale) + 4});
  for (size_t m = 0; m < meshes.size(); ++m) {
    const std::string& label = meshes[m].label;
    if (label.empty() || meshes[m].vertices.empty()) continue;
    const Box& b = bodies[m];
    const int w = CalcTextWidth(label, scale), h = CalcTextHeight(label, scale), gap = 3 * scale;
    const int mid_x = top_x[m] - w / 2, mid_y = (b.y0 + b.y1) / 2 - h / 2;
    const int candidates[][2] = {{mid_x, b.y0 - h - gap},         {b.x1 + gap, mid_y},
                                 {b.x0 - w - gap, mid_y},         {mid_x, b.y0 - 2 * h - 2 * gap},
                                 {mid_x, b.y0 - 3 * h - 3 * gap}, {mid_x, b.y1 + gap}};
    Box chosen{};
    bool have_fallback = false;
    for (const auto& c : candidates) {
      const int x = std::clamp(c[0], 2, std::max(2, style.width - w - 2));
      const int y = std::clamp(c[1], 2, std::max(2, style.height - h - 2));
      const Box box{x, y, x + w, y + h};
      bool free = true;
      for (int py = std::max(0, box.y0); py < std::min(style.height, box.y1) && free; ++py)
        for (int px = std::max(0, box.x0); px < std::min(style.width, box.x1) && free; ++px)
          if (raster.tag(px, py) >= 0) free = false;
      for (const Box& p : placed)
        if (box.Overlaps(p)) free = false;
      if (free || !have_fallback) chosen = box;
      if (free) break;
      have_fallback = true;
    }
    placed.push_back(chosen);
    // In a darker shade of the body's colour, so each label is told to its body.
    DrawText(image, chosen.x0, chosen.y0, label, scale, 0.6 * meshes[m].colour);
  }
}
}  // namespace

Image RenderFrame(const std::vector<RenderMesh>& meshes, const Camera& camera,
                  const std::optional<Ground>& ground, const std::string& caption,
                  const FrameStyle& style) {
  Image image(style.width, style.height, style.background);
  Rasterizer raster(image);
  // Key light from above, a little from the left and from the eye's side.
  const Vec3 light = (Vec3(-0.35, -0.25, 1.0) + 0.6 * camera.eye_direction()).normalized();
  if (ground) {
    DrawGround(*ground, camera, raster);
    DrawShadows(meshes, *ground, camera, raster);
  }
  for (size_t m = 0; m < meshes.size(); ++m) {
    raster.set_tag(static_cast<int>(m));
    DrawMesh(meshes[m], camera, light, raster);
  }
  if (style.labels) DrawLabels(meshes, camera, style, caption, raster, image);
  if (!caption.empty()) DrawText(image, kCaptionX, kCaptionY, caption, style.text_scale, kText);
  return image;
}

}  // namespace taut::render
