#include "plugin/hex_element_model.h"

namespace taut {

template class ElementModelImpl<HexElementTraits>;

namespace {
// *lattice, after checking there is one.
const HexLattice& DemandLattice(const std::shared_ptr<const HexLattice>& lattice) {
  TAUT_DEMAND(lattice != nullptr, "HexElementModel: lattice is null");
  return *lattice;
}
}  // namespace

HexElementModel::HexElementModel(std::shared_ptr<const HexLattice> lattice,
                                 const Material& material, HexRotationMethod rotation_method)
    : ElementModelImpl(lattice, HexElementTraits::CalcRestData(DemandLattice(lattice), material,
                                                               rotation_method)) {}

}  // namespace taut
