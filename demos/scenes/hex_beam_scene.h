// Paper B Fig. 3: 1 m cylindrical hex beams (12 cm diameter), fixed at x = 0, under gravity,
// compliant, energy-limited and stiff side by side.
#pragma once

#include <optional>

#include "demos/scenes/scene.h"

namespace taut {

// One beam per material, side by side along y. Figures per material: final and peak tip
// displacement, largest element energy and (limited beams) max over the run of max_e U_e/U_max.
// With light damping the beams still swing after 2 s, so the peak sag (first swing) is the figure
// that orders the materials as in paper B Fig. 3.
class HexBeamScene : public Scene {
 public:
  // A beam material of the scene.
  struct Beam {
    std::string name;
    DeformableBodySettings settings;
    std::optional<double> u_max;  // per-element energy limit [J]; none: unlimited
  };
  // Paper B's mesh: a 1 m x 12 cm cylinder cut with cell size 1/14 m gives 14 x 2 x 2 = 56 hexes
  // of 7.1 x 6 x 6 cm (every centre of the 2 x 2 cross-section grid lies inside the circle).
  static constexpr double kDefaultCellSize = 1.0 / 14.0;
  explicit HexBeamScene(const std::vector<Beam>& beams, double cell_size = kDefaultCellSize);
  // Paper B Fig. 3: linear Y = 150 kPa; limited Y = 150 kPa with U_e <= 1.0, 0.5, 0.1 J; stiff
  // linear Y = 2 MPa. Density 500 kg/m^3, nu = 0.3, mass damping 2 /s.
  static std::vector<Beam> DefaultBeams();

  // Updates the run's largest energy ratio, element energy and tip displacement.
  void Measure(double dt) override;
  std::vector<std::string> CsvColumns() const override;
  void AppendCsvValues(std::vector<double>& values) const override;
  void WriteFigures(nlohmann::json& figures) const override;
  // Pictures: start, the largest sag (first swing) and the end; seen from the tip side.
  std::vector<KeyFrame> CollectKeyFrames(int step, int num_steps) override;
  Vec3 GetCameraDirection() const override { return Vec3(1.0, -0.55, 0.35); }
  // Displacement of the tip centre (mean of the x = L nodes) of beam b [m].
  Vec3 CalcTipDisplacement(int b) const;
  // max_e U_e of beam b at its current state [J].
  double CalcMaxElementEnergy(int b) const;
  // max_e U_e/U_max of limited beam b at its current state (0 for an unlimited beam).
  double CalcMaxEnergyRatio(int b) const;
  // Largest CalcMaxEnergyRatio(b) after any step so far.
  double max_energy_ratio(int b) const { return max_ratio_[b]; }
  // Largest |tip displacement| of beam b after any step so far [m].
  double max_tip_displacement(int b) const { return max_tip_[b]; }

 private:
  std::vector<std::vector<int>> tip_nodes_;  // (num_beams) nodes at x = L
  std::vector<EnergyLimitSource*> limits_;   // (num_beams) null: unlimited
  std::vector<double> max_ratio_;            // (num_beams) over the run
  std::vector<double> max_energy_;           // (num_beams) max_e U_e over the run [J]
  std::vector<double> max_tip_;              // (num_beams) max |tip displacement| [m]
  double key_sag_ = 0.0;                     // largest sag of the key frames so far [m]
};

}  // namespace taut
