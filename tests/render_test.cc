// Pictures (demos/render): a rendered frame of a small scene is a non-empty PNG in which the body
// covers the part of the image it projects to, and nothing else looks like a body.
#include <gtest/gtest.h>
#include <stb_image.h>

#include <cmath>
#include <filesystem>

#include "demos/render/frame_renderer.h"
#include "demos/render/image_files.h"
#include "demos/render/picture_recorder.h"
#include "demos/scenes/falling_sphere_scene.h"

namespace taut::render {
namespace {

// A body pixel: body colours are saturated, ground, shadows, text and background are grey.
bool IsBodyPixel(const unsigned char* p) {
  const int hi = std::max({p[0], p[1], p[2]}), lo = std::min({p[0], p[1], p[2]});
  return hi - lo > 40;
}

TEST(RenderTest, FrameOfOneSphereCoversItsProjection) {
  FallingSphereScene scene({{"sphere", 150e3, std::nullopt}});
  SceneSurfaceExtractor extractor;
  const SceneSnapshot snapshot = extractor.Extract(scene);
  ASSERT_EQ(snapshot.deformables.size(), 1u);
  ASSERT_TRUE(snapshot.ground_z.has_value());
  FrameStyle style;
  style.width = 320;
  style.height = 180;
  style.labels = false;
  View view = MakeView({&snapshot}, scene.GetCameraDirection());
  view.camera.Fit(style.width, style.height, 10, 10);
  const std::vector<RenderMesh> meshes = snapshot.MakeMeshes();
  const Image image = RenderFrame(meshes, view.camera, view.ground, "", style);

  const std::string path =
      (std::filesystem::temp_directory_path() / "taut_render_test_frame.png").string();
  WritePng(image, path);
  ASSERT_GT(std::filesystem::file_size(path), 1000u);
  int width = 0, height = 0, channels = 0;
  unsigned char* pixels = stbi_load(path.c_str(), &width, &height, &channels, 3);
  ASSERT_NE(pixels, nullptr);
  EXPECT_EQ(width, 320);
  EXPECT_EQ(height, 180);

  // Where the sphere's surface projects to.
  double lo_x = HUGE_VAL, hi_x = -HUGE_VAL, lo_y = HUGE_VAL, hi_y = -HUGE_VAL;
  for (const Vec3& v : meshes[0].vertices) {
    const Vec3 p = view.camera.Project(v);
    lo_x = std::min(lo_x, p.x());
    hi_x = std::max(hi_x, p.x());
    lo_y = std::min(lo_y, p.y());
    hi_y = std::max(hi_y, p.y());
  }
  int inside = 0, inside_body = 0, outside_body = 0, ground = 0;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const unsigned char* p = pixels + 3 * (y * width + x);
      const bool in =
          x + 0.5 >= lo_x - 1 && x + 0.5 <= hi_x + 1 && y + 0.5 >= lo_y - 1 && y + 0.5 <= hi_y + 1;
      inside += in;
      if (IsBodyPixel(p)) (in ? inside_body : outside_body) += 1;
      if (!in && !IsBodyPixel(p) && p[0] < 250) ++ground;  // checkered ground or shadow
    }
  }
  stbi_image_free(pixels);
  std::filesystem::remove(path);
  // The camera fills the image with the sphere and its shadow: a sizeable projection that the
  // 32-hex lattice (a blocky ball) mostly covers, and no body pixel anywhere else.
  EXPECT_GT(inside, width * height / 20);
  EXPECT_GT(inside_body, inside / 2);
  EXPECT_EQ(outside_body, 0);
  EXPECT_GT(ground, width * height / 4);
}

TEST(RenderTest, RecorderWritesKeyFramesFigureAndGif) {
  FallingSphereScene scene({{"sphere", 150e3, std::nullopt}});
  const std::string dir =
      (std::filesystem::temp_directory_path() / "taut_render_test_recorder").string();
  std::filesystem::remove_all(dir);
  PictureSettings settings;
  settings.gif_frames = 4;
  PictureRecorder recorder(dir, "falling_sphere", 8, 1.0 / 240.0, settings);
  recorder.Record(scene, 0);
  for (int step = 1; step <= 8; ++step) {
    scene.Step(1.0 / 240.0);
    recorder.Record(scene, step);
  }
  const PictureReport report = recorder.Finish(scene.GetCameraDirection());
  EXPECT_EQ(report.key_frames, 2);  // start and rest (no impact within 8 steps)
  EXPECT_EQ(report.gif_frames, 5);  // steps 0, 2, 4, 6, 8
  for (const std::string& file : report.files)
    EXPECT_GT(std::filesystem::file_size(file), 100u) << file;
  EXPECT_TRUE(std::filesystem::exists(dir + "/key_00_start.png"));
  EXPECT_TRUE(std::filesystem::exists(dir + "/figure.png"));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace taut::render
