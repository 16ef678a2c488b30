// Co-rotational trilinear hexes of one body: ElementModelImpl over HexElementTraits and a
// HexLattice.
#pragma once

#include <memory>

#include "plugin/element_model_impl.h"
#include "plugin/hex_element_traits.h"

namespace taut {

extern template class ElementModelImpl<HexElementTraits>;

// ElementModel for a hex lattice with one material. Rest data (gradients, K_e: 24x24, 4608 bytes
// per hex) is computed once at construction and immutable; the per-element rotations are the
// runtime state.
class HexElementModel final : public ElementModelImpl<HexElementTraits> {
 public:
  // Validates the lattice and the material (throws InputError naming lattice.source).
  HexElementModel(std::shared_ptr<const HexLattice> lattice, const Material& material,
                  HexRotationMethod rotation_method = HexRotationMethod::kCenterPolar);

  const HexLattice* hex_lattice() const override { return &geometry(); }

  const HexLattice& lattice() const { return geometry(); }
  const HexRestElement& rest(int e) const { return rest_data().elements[e]; }
  const LameParameters& lame() const { return rest_data().lame; }
  HexRotationMethod rotation_method() const { return rest_data().rotation_method; }
};

}  // namespace taut
