// A rigid box resting on a soft, energy-limited hex sphere on the ground, with two more rigid
// boxes stacked on it: rigid-rigid contacts solved inside the deformable's island, in the same
// PGS as the sphere's limit and contact rows.
#pragma once

#include "demos/scenes/scene.h"

namespace taut {

// Figures: box heights and tilt, sphere flattening, deepest penetration of sphere nodes into the
// ground and the bottom box, max U_e/U_max, rigid rows and coupled bodies.
class BoxOnSphereScene : public Scene {
 public:
  // Sphere R = 0.5 m (cell 0.25 m), density 500, E [Pa], U_e <= u_max [J] (<= 0: unlimited);
  // boxes of 20, 10 and 5 kg (0.4, 0.3 and 0.2 m cubes).
  explicit BoxOnSphereScene(double youngs_modulus = 500e3, double u_max = 0.5);

  // Updates the run's largest penetration, box tilt, energy ratio and rigid contact rows.
  void Measure(double dt) override;
  std::vector<std::string> CsvColumns() const override;
  void AppendCsvValues(std::vector<double>& values) const override;
  void WriteFigures(nlohmann::json& figures) const override;
  // Pictures: start, the largest flattening of the sphere and the end.
  std::vector<KeyFrame> CollectKeyFrames(int step, int num_steps) override;

  const btRigidBody& box(int k) const { return *boxes_[k]; }
  // Height of box k's centre [m].
  double box_height(int k) const;
  // Largest tilt of any box from upright so far [rad].
  double max_tilt() const { return max_tilt_; }
  // Deepest penetration of a sphere node into the ground or the bottom box so far [m].
  double max_penetration() const { return max_penetration_; }
  double max_energy_ratio() const { return max_ratio_; }
  // Flattening 1 - (vertical extent)/(rest extent) of the sphere now.
  double CalcFlattening() const;

 private:
  std::vector<btRigidBody*> boxes_;
  EnergyLimitSource* limit_ = nullptr;
  double max_tilt_ = 0.0, max_penetration_ = 0.0, max_ratio_ = 0.0;
  int max_rigid_rows_ = 0;
  double key_flattening_ = 0.0;
};

}  // namespace taut
