#include "plugin/tet_element_traits.h"

namespace taut {

TetRestStiffness CalcTetRestStiffness(const TetRestElement& rest, const LameParameters& lame) {
  TetRestStiffness K0;
  for (int n = 0; n < 4; ++n)
    for (int m = 0; m < 4; ++m) K0[4 * n + m] = CalcRestStiffnessBlock(rest, lame, n, m);
  return K0;
}

void CalcRotatedTetStiffnessBlocks(const TetRestElement& rest, const LameParameters& lame,
                                   const Mat3& R, double scale, TetRestStiffness& blocks) {
  const double c_lambda = scale * rest.volume * lame.lambda;
  const double c_mu = scale * rest.volume * lame.mu;
  std::array<Vec3, 4> q;
  for (int n = 0; n < 4; ++n) q[n] = R * rest.r[n];
  // Entry (i, j) is c_lambda P_ij + c_mu P_ji + [i = j] c_mu r_n . r_m with P = q_n q_m^T exact
  // products, which commute: every block is the exact transpose of its mirror, the diagonal
  // blocks included.
  for (int n = 0; n < 4; ++n) {
    for (int m = n; m < 4; ++m) {
      const Mat3 P = q[n] * q[m].transpose();
      Mat3& K = blocks[4 * n + m];
      K = c_lambda * P + c_mu * P.transpose();
      K.diagonal().array() += c_mu * rest.r[n].dot(rest.r[m]);
      if (m != n) blocks[4 * m + n] = K.transpose();
    }
  }
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
