#include "plugin/tet_element_traits.h"

namespace taut {

TetRestStiffness CalcTetRestStiffness(const TetRestElement& rest, const LameParameters& lame) {
  TetRestStiffness K0;
  for (int n = 0; n < 4; ++n)
    for (int m = 0; m < 4; ++m) K0[4 * n + m] = CalcRestStiffnessBlock(rest, lame, n, m);
  return K0;
}

TetElementTraits::RestData TetElementTraits::CalcRestData(const TetMesh& mesh,
                                                          const Material& material) {
  material.Validate(mesh.source);
  RestData data;
  data.rest = CalcTetRestData(mesh);
  data.lame = {material.mu(), material.lambda()};
  // K0 depends only on the rest shape and the material, both fixed from here on.
  data.stiffness.reserve(data.rest.elements.size());
  for (const TetRestElement& rest : data.rest.elements)
    data.stiffness.push_back(CalcTetRestStiffness(rest, data.lame));
  return data;
}

}  // namespace taut
