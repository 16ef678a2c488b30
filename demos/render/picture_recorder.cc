#include "demos/render/picture_recorder.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "demos/render/image_files.h"

namespace taut::render {

namespace {
using Clock = std::chrono::steady_clock;
double MsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// A round tile size (1, 2 or 5 times a power of ten) near `size`.
double RoundTile(double size) {
  const double p = std::pow(10.0, std::floor(std::log10(size)));
  for (double m : {1.0, 2.0, 5.0})
    if (m * p >= size * 0.7) return m * p;
  return 10.0 * p;
}

// Room above the bodies for the caption and one row of labels [pixels].
int CalcTopMargin(const FrameStyle& style) {
  const int text = 7 * style.text_scale + 6;
  return style.labels ? 2 * text + 6 : text + 6;
}

// Columns of the figure for n key frames: pairs (e.g. anisotropic | isotropic) for 4 and 6.
int CalcFigureColumns(int n) { return (n == 4 || n == 6) ? 2 : std::min(std::max(n, 1), 3); }
}  // namespace

View MakeView(const std::vector<const SceneSnapshot*>& snapshots, const Vec3& camera_direction) {
  // Two passes over the snapshots, each making one snapshot's meshes at a time (memory).
  Eigen::AlignedBox3d bounds;
  std::optional<double> ground_z;
  bool any_moving = false;
  for (const SceneSnapshot* s : snapshots) {
    for (const RenderMesh& mesh : s->MakeMeshes()) {
      for (const Vec3& v : mesh.vertices) bounds.extend(v);
      any_moving = any_moving || !mesh.scenery;
    }
    if (s->ground_z) ground_z = ground_z ? std::max(*ground_z, *s->ground_z) : *s->ground_z;
  }
  View view{Camera(camera_direction), std::nullopt};
  if (bounds.isEmpty()) bounds.extend(Vec3::Zero());
  const double extent = std::max(bounds.sizes().maxCoeff(), 1e-3);
  Ground ground;
  ground.z = ground_z ? *ground_z : bounds.min().z() - 0.08 * extent;
  // Far enough beyond the bodies that its edge is out of the picture in most views.
  ground.lo = bounds.min().head<2>() - Eigen::Vector2d::Constant(1.5 * extent);
  ground.hi = bounds.max().head<2>() + Eigen::Vector2d::Constant(1.5 * extent);
  ground.tile = RoundTile(extent / 8.0);
  view.ground = ground;
  // The camera shows the moving bodies and their shadows; static scenery (a table) only when
  // there is nothing else.
  for (const SceneSnapshot* s : snapshots)
    for (const RenderMesh& mesh : s->MakeMeshes()) {
      if (mesh.scenery && any_moving) continue;
      for (const Vec3& v : mesh.vertices) {
        view.camera.Include(v);
        view.camera.Include(Vec3(v.x(), v.y(), ground.z));
      }
    }
  return view;
}

PictureRecorder::PictureRecorder(std::string out_dir, std::string scene_name, int num_steps,
                                 double dt, PictureSettings settings)
    : out_dir_(std::move(out_dir)),
      scene_name_(std::move(scene_name)),
      num_steps_(num_steps),
      dt_(dt),
      settings_(settings),
      gif_every_(
          std::max(1, (num_steps + settings.gif_frames - 1) / std::max(1, settings.gif_frames))) {}

void PictureRecorder::Record(Scene& scene, int step) {
  const std::vector<Scene::KeyFrame> keys = scene.CollectKeyFrames(step, num_steps_);
  const bool gif = step % gif_every_ == 0 || step == num_steps_;
  if (keys.empty() && !gif) return;
  const Clock::time_point start = Clock::now();
  auto snapshot = std::make_shared<const SceneSnapshot>(extractor_.Extract(scene));
  if (gif) gif_.push_back({step, snapshot, "", ""});
  for (const Scene::KeyFrame& key : keys) {
    auto same = std::find_if(keys_.begin(), keys_.end(),
                             [&](const Frame& f) { return f.slot == key.slot; });
    if (same != keys_.end()) keys_.erase(same);
    keys_.push_back({step, snapshot, key.slot, key.caption});
  }
  ms_capture_ += MsSince(start);
}

std::string PictureRecorder::FormatCaption(const Frame& frame) const {
  char time[48];
  std::snprintf(time, sizeof(time), "t = %.3f s", frame.step * dt_);
  return frame.caption.empty() ? scene_name_ + "  " + time
                               : std::string(time) + ": " + frame.caption;
}

PictureReport PictureRecorder::Finish(const Vec3& camera_direction) {
  namespace fs = std::filesystem;
  fs::create_directories(out_dir_);
  PictureReport report;
  report.ms_capture = ms_capture_;
  std::stable_sort(keys_.begin(), keys_.end(),
                   [](const Frame& a, const Frame& b) { return a.step < b.step; });
  std::vector<const SceneSnapshot*> all;
  for (const Frame& f : gif_) all.push_back(f.snapshot.get());
  for (const Frame& f : keys_) all.push_back(f.snapshot.get());
  if (all.empty()) return report;
  View view = MakeView(all, camera_direction);
  // Key frames, one PNG each.
  const FrameStyle& key_style = settings_.key_style;
  view.camera.Fit(key_style.width, key_style.height, key_style.height / 20,
                  CalcTopMargin(key_style));
  double ms_render = 0.0, ms_png = 0.0;
  for (size_t k = 0; k < keys_.size(); ++k) {
    Clock::time_point start = Clock::now();
    const Image image = RenderFrame(keys_[k].snapshot->MakeMeshes(), view.camera, view.ground,
                                    FormatCaption(keys_[k]), key_style);
    ms_render += MsSince(start);
    char name[32];
    std::snprintf(name, sizeof(name), "key_%02d_", static_cast<int>(k));
    const std::string path = out_dir_ + "/" + name + keys_[k].slot + ".png";
    start = Clock::now();
    WritePng(image, path);
    ms_png += MsSince(start);
    report.files.push_back(path);
  }
  report.key_frames = static_cast<int>(keys_.size());
  if (!keys_.empty()) {
    report.ms_render_frame = ms_render / keys_.size();
    report.ms_write_png = ms_png / keys_.size();
    // The figure: the key frames as tiles, in rows.
    const FrameStyle& tile = settings_.tile_style;
    const int n = static_cast<int>(keys_.size()), columns = CalcFigureColumns(n);
    const int rows = (n + columns - 1) / columns;
    Image figure(columns * tile.width, rows * tile.height, tile.background);
    view.camera.Fit(tile.width, tile.height, tile.height / 20, CalcTopMargin(tile));
    for (int k = 0; k < n; ++k)
      Blit(RenderFrame(keys_[k].snapshot->MakeMeshes(), view.camera, view.ground,
                       FormatCaption(keys_[k]), tile),
           (k % columns) * tile.width, (k / columns) * tile.height, figure);
    WritePng(figure, out_dir_ + "/figure.png");
    report.files.push_back(out_dir_ + "/figure.png");
  }
  // The animation.
  const FrameStyle& gif_style = settings_.gif_style;
  view.camera.Fit(gif_style.width, gif_style.height, gif_style.height / 20,
                  CalcTopMargin(gif_style));
  GifWriter gif(out_dir_ + "/run.gif", settings_.gif_delay_cs);
  double ms_gif_render = 0.0;
  for (const Frame& f : gif_) {
    const Clock::time_point start = Clock::now();
    const Image image = RenderFrame(f.snapshot->MakeMeshes(), view.camera, view.ground,
                                    FormatCaption(f), gif_style);
    ms_gif_render += MsSince(start);
    gif.AddFrame(image);
  }
  report.gif_frames = gif.num_frames();
  if (!gif_.empty()) report.ms_render_gif_frame = ms_gif_render / gif_.size();
  const Clock::time_point start = Clock::now();
  gif.Finish();
  report.ms_write_gif = MsSince(start);
  if (report.gif_frames > 0) report.files.push_back(out_dir_ + "/run.gif");
  return report;
}

}  // namespace taut::render
