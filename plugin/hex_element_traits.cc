#include "plugin/hex_element_traits.h"

namespace taut {

HexElementTraits::RestData HexElementTraits::CalcRestData(const HexLattice& lattice,
                                                          const Material& material,
                                                          HexRotationMethod rotation_method) {
  ValidateHexLattice(lattice);
  material.Validate(lattice.source);
  RestData data;
  data.lame = {material.mu(), material.lambda()};
  data.rotation_method = rotation_method;
  data.elements.reserve(lattice.hexes.size());
  for (const auto& hex : lattice.hexes) {
    HexNodes X;
    for (int a = 0; a < 8; ++a) X[a] = lattice.nodes[hex[a]];
    data.elements.push_back(CalcHexRestElement(X, data.lame));
  }
  ShareEqualHexStiffnesses(data.elements);
  return data;
}

}  // namespace taut
