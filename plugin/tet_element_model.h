// Co-rotational linear tets of one body (corotated_tet_element.h kernels over a TetMesh).
#pragma once

#include <memory>

#include "plugin/corotated_tet_element.h"
#include "plugin/element_model.h"
#include "plugin/material.h"

namespace taut {

// ElementModel for a tet mesh with one material. Rest data is shared and immutable; the
// per-element rotations are the runtime state.
class TetElementModel final : public ElementModel {
 public:
  // Validates the mesh and the material (throws InputError naming mesh.source).
  TetElementModel(std::shared_ptr<const TetMesh> mesh, const Material& material);

  int num_nodes() const override { return static_cast<int>(mesh_->nodes.size()); }
  int num_elements() const override { return static_cast<int>(mesh_->tets.size()); }
  int nodes_per_element() const override { return 4; }
  const int* element_nodes(int e) const override { return mesh_->tets[e].data(); }
  const VecX& rest_positions() const override { return rest_positions_; }
  void CalcLumpedMass(double density, VecX& mass) const override;
  double UpdateRotationsAndAddForces(const VecX& x, VecX& f) override;
  void AddScaledStiffness(double scale, const std::vector<int>& index_map,
                          double* values) const override;
  void AddScaledStiffnessTimes(double scale, const VecX& v, VecX& out) const override;
  double CalcEnergy(const VecX& x) const override;

  const TetMesh& mesh() const { return *mesh_; }
  const TetRestData& rest() const { return rest_; }
  const LameParameters& lame() const { return lame_; }
  // Rotation of element e from the last UpdateRotationsAndAddForces.
  const Mat3& rotation(int e) const { return rotations_[e]; }
  // Node positions of element e gathered from x.
  std::array<Vec3, 4> GatherElement(const VecX& x, int e) const;

 private:
  std::shared_ptr<const TetMesh> mesh_;
  TetRestData rest_;
  LameParameters lame_;
  VecX rest_positions_;
  std::vector<Mat3> rotations_;  // (num_tets)
};

}  // namespace taut
