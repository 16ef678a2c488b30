// Co-rotational linear tets of one body: ElementModelImpl over TetElementTraits and a TetMesh.
#pragma once

#include <memory>

#include "plugin/element_model_impl.h"
#include "plugin/tet_element_traits.h"

namespace taut {

extern template class ElementModelImpl<TetElementTraits>;

// ElementModel for a tet mesh with one material. Rest data (r_n, volumes, K0) is computed once at
// construction and immutable; the per-element rotations are the runtime state.
class TetElementModel final : public ElementModelImpl<TetElementTraits> {
 public:
  // Validates the mesh and the material (throws InputError naming mesh.source).
  TetElementModel(std::shared_ptr<const TetMesh> mesh, const Material& material);

  const TetMesh* tet_mesh() const override { return &geometry(); }
  const TetElementModel* tet_model() const override { return this; }

  const TetMesh& mesh() const { return geometry(); }
  const TetRestData& rest() const { return rest_data().rest; }
  const LameParameters& lame() const { return rest_data().lame; }
  // Stored rest stiffness block K0_ab of element e (CalcRestStiffnessBlock at construction).
  const Mat3& rest_stiffness_block(int e, int a, int b) const {
    return TetElementTraits::RestStiffnessBlock(rest_data(), e, a, b);
  }
};

}  // namespace taut
