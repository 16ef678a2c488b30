// A headless demo scene: built from options, stepped, and summarized (docs/architecture.md §7).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "demos/scenes/bullet_world_holder.h"
#include "plugin/contact_surface.h"
#include "plugin/surface_mesh.h"
#include "plugin/vtk_collection_writer.h"

namespace taut {

// One scene of the demo binary, benchmarks and tests.
class Scene {
 public:
  virtual ~Scene() = default;
  // Advances the scene by one step of length dt: Simulate(dt), then Measure(dt).
  void Step(double dt);
  // The simulation of one step of length dt: the scene's drivers (e.g. a kinematic bone's motion)
  // and one Bullet substep. A step's timing (ms_step) covers this part only.
  virtual void Simulate(double dt);
  // The scene's own measurements of the step Simulate(dt) just took (energies, reactions, maxima
  // for the figures) and the scene events decided by them; outside the timed part.
  virtual void Measure(double /*dt*/) {}
  // Names of the scene-specific per-step CSV columns.
  virtual std::vector<std::string> CsvColumns() const { return {}; }
  // Values for CsvColumns() after the current step.
  virtual void AppendCsvValues(std::vector<double>& /*values*/) const {}
  // Scene figures for summary.json (e.g. tip_displacement_m per material).
  virtual void WriteFigures(nlohmann::json& figures) const = 0;
  // Writes VTK files of every deformable body for frame `frame` into dir, and adds each to the
  // ParaView collection dir/<body>.pvd (dir/<body>_surface.pvd for an embedded surface) at `time`
  // (the simulated time in seconds; negative: the frame number), so a run opens as one animation.
  virtual void WriteVtkFrame(const std::string& dir, int frame, double time = -1.0) const;
  // A picture of the run (--png): key frames with the same slot replace each other, so a scene
  // can keep e.g. the frame of the largest sag so far.
  struct KeyFrame {
    std::string slot;     // file name part, e.g. "impact"
    std::string caption;  // text drawn on the picture
  };
  // Key frames at the state after step `step` of num_steps (0: the initial state); called once per
  // step, outside the timed Step. Default: first, middle and last step.
  virtual std::vector<KeyFrame> CollectKeyFrames(int step, int num_steps);
  // Direction from the scene towards the camera of the pictures (world frame, z up).
  virtual Vec3 GetCameraDirection() const { return Vec3(0.45, -1.0, 0.5); }

  // Embeds `surface` in tet or hex body `body` (MakeEmbeddedBodyContactSurface: 4 barycentric or
  // 8 trilinear weights per vertex) so that WriteVtkFrame also writes the deformed surface (VTK
  // and OBJ) each frame. Returns its index.
  int AttachEmbeddedSurface(int body, const SurfaceMesh& surface);
  int num_embedded_surfaces() const { return static_cast<int>(embedded_.size()); }
  // Deformed vertex positions of embedded surface i at the bodies' current positions.
  std::vector<Vec3> CalcEmbeddedSurfacePositions(int i) const;
  // Body index and embedding of surface i (one point per vertex, a weighted sum of body nodes).
  int embedded_surface_body(int i) const { return embedded_[i].body; }
  const ContactSurface& embedded_surface(int i) const { return embedded_[i].surface; }

  DeformableWorld& world() { return holder_.world; }
  const DeformableWorld& world() const { return holder_.world; }
  // The world the scene steps, as generic code sees it (VTK frames, state hashes, pictures, the
  // demo's statistics): world() unless a scene steps a world of its own (GripperScene: a
  // DeformableMultiBodyWorld), which then overrides all six.
  virtual int num_deformable_bodies() const { return world().num_deformable_bodies(); }
  virtual const DeformableBody& deformable_body(int b) const { return world().deformable_body(b); }
  virtual const btCollisionObjectArray& collision_objects() const {
    return world().getCollisionObjectArray();
  }
  virtual const StepStats& last_step_stats() const { return world().last_step_stats(); }
  virtual SqpSettings& mutable_solver_settings() { return world().mutable_solver_settings(); }
  virtual void SetThreadCount(int threads) { world().SetThreadCount(threads); }
  // FNV-1a hash of every deformable x, v and every rigid transform and velocity (bitwise).
  uint64_t CalcStateHash() const;

 protected:
  BulletWorldHolder holder_;
  // A surface embedded in a tet or hex body.
  struct EmbeddedSurfaceOutput {
    int body;
    ContactSurface surface;
  };
  std::vector<EmbeddedSurfaceOutput> embedded_;
  // The .pvd collections WriteVtkFrame extends.
  mutable VtkSeriesWriter vtk_series_;
};

// Key frames of a figure showing the extreme of a scene quantity: "start" at step 0, `slot` with
// `caption` whenever `value` exceeds *peak (which it then raises) and "end" with `end_caption`
// (only the peak frame, captioned "<caption>, end", when the value still grows at the last step).
std::vector<Scene::KeyFrame> CollectPeakKeyFrames(int step, int num_steps, double value,
                                                  double* peak, const std::string& slot,
                                                  const std::string& caption,
                                                  const std::string& end_caption = "end");

// Settings of a scene body: name, E [Pa], nu = 0.3, density [kg/m^3], Rayleigh alpha [1/s].
DeformableBodySettings MakeSceneBodySettings(const std::string& name, double youngs_modulus,
                                             double density, double mass_damping = 0.0);

// Mean displacement x - X of the listed nodes of a body [m].
Vec3 CalcMeanDisplacement(const DeformableBody& body, const std::vector<int>& nodes);

// Command-line options of a scene run.
struct SceneOptions {
  int steps = 0;    // 0: the scene's default
  double dt = 0.0;  // 0: the scene's default [s]
};

// A registered scene: name, one-line description, defaults and factory.
struct SceneInfo {
  std::string name;
  std::string description;
  int default_steps;
  double default_dt;
  std::function<std::unique_ptr<Scene>()> make;
};

// Every scene, in the order `taut-demo --list` prints them.
const std::vector<SceneInfo>& SceneRegistry();
// Finds a scene by name; throws InputError listing the known names when missing.
const SceneInfo& FindScene(const std::string& name);

}  // namespace taut
