// Paper A's cantilever (Fig. 2): 1 m x 0.2 m x 0.2 m tet beams, fixed at x = 0, under gravity.
#pragma once

#include <optional>

#include "demos/scenes/scene.h"

namespace taut {

// One beam per material, side by side along y. Figures: tip displacement per material.
class TetBeamScene : public Scene {
 public:
  // A beam material of the scene.
  struct Beam {
    std::string name;
    DeformableBodySettings settings;
    std::optional<StrainLimitSettings> limits;  // none: unlimited
  };
  // Beams 1 x 0.2 x 0.2 m cut into cells_x x 2 x 2 cubes (6 tets each; 10 -> 240 tets).
  explicit TetBeamScene(const std::vector<Beam>& beams, int cells_x = 10, int cells_yz = 2);
  // Paper A Fig. 2: stiff E = 200 kPa; compliant E = 5 kPa unlimited; compliant anisotropic
  // (free along the beam axis x, 0.96..1.04 on y and z); compliant isotropic (0.96..1.04 on all).
  // Density 1000 kg/m^3, nu = 0.3.
  static std::vector<Beam> DefaultBeams();

  // Updates the run's largest tip displacement per beam.
  void Measure(double dt) override;
  std::vector<std::string> CsvColumns() const override;
  void AppendCsvValues(std::vector<double>& values) const override;
  void WriteFigures(nlohmann::json& figures) const override;
  // Pictures: start, the largest sag (first swing) and the end; seen from the tip side.
  std::vector<KeyFrame> CollectKeyFrames(int step, int num_steps) override;
  Vec3 GetCameraDirection() const override { return Vec3(1.0, -0.55, 0.35); }
  // Displacement of the tip centre (mean of the x = L nodes) of beam b [m].
  Vec3 CalcTipDisplacement(int b) const;
  // Current distance between the centres of the clamped face and the tip face of beam b [m].
  double CalcLength(int b) const;

 private:
  std::vector<std::vector<int>> tip_nodes_;  // (num_beams) nodes at x = L
  std::vector<bool> limited_;                // (num_beams) has strain limits
  std::vector<double> max_tip_;              // largest |tip displacement| seen [m]
  double key_sag_ = 0.0;                     // largest sag of the key frames so far [m]
};

}  // namespace taut
