// Pictures of a demo run (taut-demo --png): the scene's key frames as PNGs, a figure with the key
// frames side by side and an animated GIF of the run, all seen by one camera.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "demos/render/frame_renderer.h"
#include "demos/render/scene_surfaces.h"

namespace taut::render {

// Sizes and pacing of the pictures.
struct PictureSettings {
  FrameStyle key_style;                                    // key frames: 640 x 360
  FrameStyle tile_style{400, 225, 1, true, Vec3::Ones()};  // figure.png tiles
  FrameStyle gif_style{320, 180, 1, false, Vec3::Ones()};  // run.gif frames
  int gif_frames = 60;                                     // about this many GIF frames per run
  int gif_delay_cs = 8;
};

// What Finish() wrote and what it cost.
struct PictureReport {
  std::vector<std::string> files;
  int key_frames = 0, gif_frames = 0;
  double ms_capture = 0.0;       // surface extraction during the run, total
  double ms_render_frame = 0.0;  // mean rasterization of one 640 x 360 key frame
  double ms_render_gif_frame = 0.0;
  double ms_write_png = 0.0;  // mean PNG encoding of one key frame
  double ms_write_gif = 0.0;  // gnuplot's GIF encoding, total
};

// Records snapshots while a scene runs and writes the pictures at the end. Rendering happens in
// Finish(), after the run; Record() only copies surfaces (outside the timed step).
class PictureRecorder {
 public:
  // Pictures of a run of num_steps steps of dt into out_dir (key_*.png, figure.png, run.gif).
  PictureRecorder(std::string out_dir, std::string scene_name, int num_steps, double dt,
                  PictureSettings settings = PictureSettings());
  // Call with step 0 before the first step and after every step: keeps a GIF frame every
  // num_steps / gif_frames steps and the scene's key frames (Scene::CollectKeyFrames).
  void Record(Scene& scene, int step);
  // Renders and writes everything seen from `camera_direction`.
  PictureReport Finish(const Vec3& camera_direction);

 private:
  struct Frame {
    int step;
    std::shared_ptr<const SceneSnapshot> snapshot;
    std::string slot, caption;
  };
  std::string FormatCaption(const Frame& frame) const;

  std::string out_dir_, scene_name_;
  int num_steps_;
  double dt_;
  PictureSettings settings_;
  int gif_every_;
  SceneSurfaceExtractor extractor_;
  std::vector<Frame> gif_, keys_;
  double ms_capture_ = 0.0;
};

// The camera and ground for a set of snapshots: the camera sees every moving body in every
// snapshot and its shadow (static scenery may be cut off); the ground is the scenes' ground plane
// (or a floor just below the lowest point) reaching well beyond the bodies.
struct View {
  Camera camera;
  std::optional<Ground> ground;
};
View MakeView(const std::vector<const SceneSnapshot*>& snapshots, const Vec3& camera_direction);

}  // namespace taut::render
