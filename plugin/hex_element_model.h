// Co-rotational trilinear hexes of one body (corotated_hex_element.h kernels over a HexLattice).
#pragma once

#include <memory>
#include <vector>

#include "plugin/corotated_hex_element.h"
#include "plugin/element_model.h"
#include "plugin/material.h"

namespace taut {

// ElementModel for a hex lattice with one material. Rest data (gradients, K_e: 24x24, 4608 bytes
// per hex) is computed once at construction and immutable; the per-element rotations are the
// runtime state.
class HexElementModel final : public ElementModel {
 public:
  // Validates the lattice and the material (throws InputError naming lattice.source).
  HexElementModel(std::shared_ptr<const HexLattice> lattice, const Material& material,
                  HexRotationMethod rotation_method = HexRotationMethod::kCenterPolar);

  int num_nodes() const override { return static_cast<int>(lattice_->nodes.size()); }
  int num_elements() const override { return static_cast<int>(lattice_->hexes.size()); }
  int nodes_per_element() const override { return 8; }
  const int* element_nodes(int e) const override { return lattice_->hexes[e].data(); }
  const VecX& rest_positions() const override { return rest_positions_; }
  double element_rest_volume(int e) const override { return rest_[e].volume; }
  void CalcLumpedMass(double density, VecX& mass) const override;
  double UpdateRotationsAndAddForces(const VecX& x, VecX& f) override;
  void AddScaledStiffness(double scale, const std::vector<int>& index_map,
                          double* values) const override;
  void AddScaledStiffnessTimes(double scale, const VecX& v, VecX& out) const override;
  double CalcEnergy(const VecX& x) const override;

  const HexLattice& lattice() const { return *lattice_; }
  const HexRestElement& rest(int e) const { return rest_[e]; }
  const LameParameters& lame() const { return lame_; }
  HexRotationMethod rotation_method() const { return rotation_method_; }
  // Rotation of element e from the last UpdateRotationsAndAddForces.
  const Mat3& rotation(int e) const { return rotations_[e]; }
  // Node positions of element e gathered from x.
  HexNodes GatherElement(const VecX& x, int e) const;

 private:
  std::shared_ptr<const HexLattice> lattice_;
  std::vector<HexRestElement> rest_;  // (num_hexes)
  LameParameters lame_;
  HexRotationMethod rotation_method_;
  VecX rest_positions_;
  std::vector<Mat3> rotations_;  // (num_hexes)
};

}  // namespace taut
