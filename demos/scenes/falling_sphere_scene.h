// Paper B Fig. 4: a hex sphere (R = 1 m, density 500 kg/m^3) dropped from 2 m onto a static
// ground: Y = 150 kPa, Y = 1 MPa, and Y = 150 kPa with U_e <= 500 J, side by side.
#pragma once

#include <optional>

#include "demos/scenes/scene.h"

namespace taut {

// Figures per material: largest flattening 1 - (vertical extent)/(2R), bounce height (highest
// bottom point after the first impact), deepest penetration, max U_e/U_max.
class FallingSphereScene : public Scene {
 public:
  // A sphere material of the scene.
  struct Sphere {
    std::string name;
    double youngs_modulus;
    std::optional<double> u_max;  // per-element energy limit [J]
  };
  // Cell 0.5 m: 4 x 4 x 4 grid, 32 hexes kept (paper: about 27).
  explicit FallingSphereScene(const std::vector<Sphere>& spheres, double cell_size = 0.5);
  static std::vector<Sphere> DefaultSpheres();

  // Updates landing, bounce and the run's extremes (lowest point, flattening, energy ratio).
  void Measure(double dt) override;
  std::vector<std::string> CsvColumns() const override;
  void AppendCsvValues(std::vector<double>& values) const override;
  void WriteFigures(nlohmann::json& figures) const override;
  // Pictures: start, impact (largest flattening) and rest (the end).
  std::vector<KeyFrame> CollectKeyFrames(int step, int num_steps) override;

  // Lowest and highest node z of sphere s [m].
  double CalcBottom(int s) const;
  double CalcTop(int s) const;
  double max_flattening(int s) const { return max_flattening_[s]; }
  double bounce_height(int s) const { return bounce_[s]; }
  double deepest_penetration(int s) const { return deepest_[s]; }
  double max_energy_ratio(int s) const { return max_ratio_[s]; }

 private:
  std::vector<EnergyLimitSource*> limits_;
  std::vector<bool> landed_;
  std::vector<double> max_flattening_, bounce_, deepest_, max_ratio_;
  double key_flattening_ = 0.0;
};

}  // namespace taut
