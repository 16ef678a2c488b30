// Paper B Fig. 6: the Stanford armadillo (2 m tall, voxelized to ~365 hexes, density 500 kg/m^3)
// dropped onto a static ground: Y = 500 kPa, Y = 5 MPa, Y = 500 kPa with U_e <= 100 J.
#pragma once

#include <optional>

#include "demos/scenes/scene.h"

namespace taut {

// Needs data/armadillo.off (scripts/fetch_armadillo.sh). Figures per material: number of hexes,
// largest flattening, deepest penetration, max U_e/U_max. The scan is embedded in each lattice
// and written with --vtk.
class ArmadilloScene : public Scene {
 public:
  struct Material {
    std::string name;
    double youngs_modulus;
    std::optional<double> u_max;  // per-element energy limit [J]
  };
  // `off_path` defaults to <source>/data/armadillo.off; throws InputError naming the fetch script
  // when the file is missing.
  explicit ArmadilloScene(const std::vector<Material>& materials, const std::string& off_path = "");
  static std::vector<Material> DefaultMaterials();

  // Updates the run's lowest point and largest flattening and energy ratio.
  void Measure(double dt) override;
  void WriteFigures(nlohmann::json& figures) const override;
  // Pictures: start, impact (largest flattening) and rest (the end).
  std::vector<KeyFrame> CollectKeyFrames(int step, int num_steps) override;
  double max_flattening(int b) const { return max_flattening_[b]; }
  double deepest(int b) const { return deepest_[b]; }
  double max_energy_ratio(int b) const { return max_ratio_[b]; }

 private:
  std::vector<EnergyLimitSource*> limits_;
  std::vector<double> rest_height_, max_flattening_, deepest_, max_ratio_;
  double key_flattening_ = 0.0;
};

}  // namespace taut
