// A headless demo scene: built from options, stepped, and summarized (DESIGN.md "Demo output").
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "demos/scenes/bullet_world_holder.h"
#include "plugin/embedded_surface.h"
#include "plugin/surface_mesh.h"

namespace taut {

// One scene of the demo binary, benchmarks and tests.
class Scene {
 public:
  virtual ~Scene() = default;
  // Advances the scene by one step of length dt (one Bullet substep).
  virtual void Step(double dt);
  // Names of the scene-specific per-step CSV columns.
  virtual std::vector<std::string> CsvColumns() const { return {}; }
  // Values for CsvColumns() after the current step.
  virtual void AppendCsvValues(std::vector<double>& /*values*/) const {}
  // Scene figures for summary.json (e.g. tip_displacement_m per material).
  virtual void WriteFigures(nlohmann::json& figures) const = 0;
  // Writes VTK files of every deformable body for frame `frame` into dir.
  virtual void WriteVtkFrame(const std::string& dir, int frame) const;

  // Embeds `surface` in the lattice of hex body `body` (trilinear weights per vertex) so that
  // WriteVtkFrame also writes the deformed surface (VTK and OBJ) each frame. Returns its index.
  int AttachEmbeddedSurface(int body, const SurfaceMesh& surface);
  int num_embedded_surfaces() const { return static_cast<int>(embedded_.size()); }
  // Deformed vertex positions of embedded surface i at the bodies' current positions.
  std::vector<Vec3> CalcEmbeddedSurfacePositions(int i) const;

  DeformableWorld& world() { return holder_.world; }
  const DeformableWorld& world() const { return holder_.world; }
  // FNV-1a hash of every deformable x, v and every rigid transform and velocity (bitwise).
  uint64_t CalcStateHash() const;

 protected:
  BulletWorldHolder holder_;
  // A surface embedded in a hex body.
  struct EmbeddedSurfaceOutput {
    int body;
    EmbeddedSurface surface;
  };
  std::vector<EmbeddedSurfaceOutput> embedded_;
};

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
