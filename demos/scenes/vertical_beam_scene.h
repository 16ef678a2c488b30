// Paper A Fig. 4: a compliant column (E = 10 kPa, nu = 0.3) fixed at its bottom collapses under
// gravity; one transverse axis (x) is limited to 0.95..1.05, the others are free. One column per
// strain projection mode, side by side.
#pragma once

#include "demos/scenes/scene.h"

namespace taut {

class VerticalBeamScene : public Scene {
 public:
  // Columns 0.2 x 0.2 x 1 m of cells_xy x cells_xy x cells_z cubes (6 tets each), one per mode.
  explicit VerticalBeamScene(const std::vector<StrainProjection>& modes, int cells_xy = 2,
                             int cells_z = 10);
  // The four modes of the issue.
  static std::vector<StrainProjection> AllModes();

  // Updates the first violation step and the largest limited-axis strain and violation.
  void Measure(double dt) override;
  std::vector<std::string> CsvColumns() const override;
  void AppendCsvValues(std::vector<double>& values) const override;
  void WriteFigures(nlohmann::json& figures) const override;
  // Pictures: start, the first limit violation of each mode (one frame when they coincide) and the
  // end.
  std::vector<KeyFrame> CollectKeyFrames(int step, int num_steps) override;

  // Largest strain |G e_x| - 1 over the elements of column c now.
  double CalcLimitedAxisStrain(int c) const;
  // Height of the column's top centre above the ground [m].
  double CalcTopHeight(int c) const;
  // First step at which the unconstrained prediction violated a limit row (-1: never).
  int first_violation_step(int c) const { return first_violation_[c]; }
  // Largest limited-axis strain seen so far.
  double max_limited_axis_strain(int c) const { return max_strain_[c]; }

 private:
  std::vector<StrainProjection> modes_;
  std::vector<StrainLimitSource*> limits_;
  std::vector<std::vector<int>> top_nodes_;
  std::vector<int> first_violation_;
  std::vector<double> max_strain_;
  std::vector<int> max_rows_;
  std::vector<double> max_violation_after_;
  int step_ = 0;
};

}  // namespace taut
