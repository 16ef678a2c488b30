// Paper B Fig. 5: a high-resolution hex sphere (R = 1 m, 280 hexes, density 500 kg/m^3) of an
// extremely compliant material (Y = 50 kPa) dropped onto a static ground, without and with the
// per-element energy limit U_e <= 50 J, side by side.
#pragma once

#include <memory>
#include <optional>

#include "demos/scenes/scene.h"

namespace taut {

// Figures per sphere: largest and final flattening 1 - (vertical extent)/(rest extent), final top
// height, max U_e/U_max (for the unlimited sphere measured against the limited one's U_max),
// smallest volume ratio det(dx/ds)/det(dX/ds) over the Gauss points (volume loss; <= 0 means an
// inverted hex), deepest penetration; and the mean world step time.
class CollapsingSphereScene : public Scene {
 public:
  // A sphere material of the scene.
  struct Sphere {
    std::string name;
    double youngs_modulus;        // [Pa]
    std::optional<double> u_max;  // per-element energy limit [J]; none: unlimited
  };
  // Spheres of radius 1 m on a cell_size grid (0.25 m: 8^3 grid, 280 hexes kept), their bottom
  // drop_height above the ground at t = 0, 3 m apart along x. Throws InputError for a non-positive
  // cell size or a negative drop height.
  explicit CollapsingSphereScene(const std::vector<Sphere>& spheres, double cell_size = 0.25,
                                 double drop_height = 0.5);
  // Paper B Fig. 5: Y = 50 kPa linear, and Y = 50 kPa with U_e <= 50 J.
  static std::vector<Sphere> DefaultSpheres();
  // U_max of the energy meter of unlimited spheres [J] (the paper's limit).
  static constexpr double kMeterEnergy = 50.0;

  // Updates the run's extremes (lowest point, flattening, energy and volume ratios, step time).
  void Measure(double dt) override;
  std::vector<std::string> CsvColumns() const override;
  void AppendCsvValues(std::vector<double>& values) const override;
  void WriteFigures(nlohmann::json& figures) const override;
  // Pictures: start, impact (largest flattening) and rest (the end).
  std::vector<KeyFrame> CollectKeyFrames(int step, int num_steps) override;

  int num_spheres() const { return static_cast<int>(meters_.size()); }
  double max_flattening(int s) const { return max_flattening_[s]; }
  // 1 - (vertical extent now)/(rest extent).
  double CalcFlattening(int s) const;
  // Highest node z of sphere s now [m].
  double CalcTop(int s) const;
  double max_energy_ratio(int s) const { return max_ratio_[s]; }
  double min_volume_ratio(int s) const { return min_volume_ratio_[s]; }
  double deepest_penetration(int s) const { return -deepest_[s]; }
  double mean_ms_step() const { return steps_ > 0 ? ms_sum_ / steps_ : 0.0; }

 private:
  // Lowest and highest node z of sphere s.
  void CalcZRange(int s, double& lo, double& hi) const;
  // Smallest det(dx/ds)/det(dX/ds) over every hex Gauss point of sphere s.
  double CalcMinVolumeRatio(int s) const;

  bool limited(int s) const { return limits_[s] != nullptr; }

  std::vector<EnergyLimitSource*> limits_;                  // world's limits, or null
  std::vector<std::unique_ptr<EnergyLimitSource>> meters_;  // U_e/U_max of every sphere
  std::vector<double> rest_extent_, max_flattening_, max_ratio_, min_volume_ratio_, deepest_;
  int steps_ = 0;
  double ms_sum_ = 0.0;
  double key_flattening_ = 0.0;
};

}  // namespace taut
