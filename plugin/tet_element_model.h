// Co-rotational linear tets of one body (corotated_tet_element.h kernels over a TetMesh).
#pragma once

#include <array>
#include <memory>
#include <vector>

#include "plugin/corotated_tet_element.h"
#include "plugin/element_model.h"
#include "plugin/material.h"

namespace taut {

// Rest stiffness K0 of one tet as its 16 3x3 blocks, block (n,m) = CalcRestStiffnessBlock(n, m)
// at index 4 n + m (1152 bytes) [N/m].
using TetRestStiffness = std::array<Mat3, 16>;

// The 16 blocks K0_nm of one tet, each exactly as CalcRestStiffnessBlock computes it.
TetRestStiffness CalcTetRestStiffness(const TetRestElement& rest, const LameParameters& lame);

// ElementModel for a tet mesh with one material. Rest data (r_n, volumes, K0) is computed once at
// construction and immutable; the per-element rotations are the runtime state.
class TetElementModel final : public ElementModel {
 public:
  // Validates the mesh and the material (throws InputError naming mesh.source).
  TetElementModel(std::shared_ptr<const TetMesh> mesh, const Material& material);

  int num_nodes() const override { return static_cast<int>(mesh_->nodes.size()); }
  int num_elements() const override { return static_cast<int>(mesh_->tets.size()); }
  int nodes_per_element() const override { return 4; }
  const int* element_nodes(int e) const override { return mesh_->tets[e].data(); }
  const VecX& rest_positions() const override { return rest_positions_; }
  double element_rest_volume(int e) const override { return rest_.elements[e].volume; }
  void CalcLumpedMass(double density, VecX& mass) const override;
  double UpdateRotationsAndAddForces(const VecX& x, VecX& f) override;
  void AddScaledStiffness(double scale, const std::vector<int>& index_map,
                          double* values) const override;
  void AddScaledStiffnessTimes(double scale, const VecX& v, VecX& out) const override;
  double CalcEnergy(const VecX& x) const override;

  const TetMesh& mesh() const { return *mesh_; }
  const TetRestData& rest() const { return rest_; }
  const LameParameters& lame() const { return lame_; }
  // Stored rest stiffness block K0_ab of element e (CalcRestStiffnessBlock at construction).
  const Mat3& rest_stiffness_block(int e, int a, int b) const {
    return rest_stiffness_[e][4 * a + b];
  }
  // Rotation of element e from the last UpdateRotationsAndAddForces.
  const Mat3& rotation(int e) const { return rotations_[e]; }
  // Node positions of element e gathered from x.
  std::array<Vec3, 4> GatherElement(const VecX& x, int e) const;

 private:
  std::shared_ptr<const TetMesh> mesh_;
  TetRestData rest_;
  LameParameters lame_;
  VecX rest_positions_;
  std::vector<TetRestStiffness> rest_stiffness_;  // (num_tets), from rest_ and lame_
  std::vector<Mat3> rotations_;                   // (num_tets)
};

}  // namespace taut
