#include "plugin/tet_rest_data.h"

#include <Eigen/LU>

namespace taut {

TetRestData CalcTetRestData(const TetMesh& mesh) {
  ValidateTetMesh(mesh);
  TetRestData rest;
  rest.elements.resize(mesh.tets.size());
  for (size_t e = 0; e < mesh.tets.size(); ++e) {
    const auto& t = mesh.tets[e];
    const Vec3& X4 = mesh.nodes[t[3]];
    Mat3 X0;
    X0 << mesh.nodes[t[0]] - X4, mesh.nodes[t[1]] - X4, mesh.nodes[t[2]] - X4;
    const Mat3 X0_inv = X0.inverse();
    TetRestElement& el = rest.elements[e];
    for (int n = 0; n < 3; ++n) el.r[n] = X0_inv.row(n).transpose();
    el.r[3] = -(el.r[0] + el.r[1] + el.r[2]);
    el.volume = X0.determinant() / 6.0;
  }
  return rest;
}

Mat3 CalcTetDeformationGradient(const std::array<Vec3, 4>& r, const std::array<Vec3, 4>& x) {
  Mat3 G = x[0] * r[0].transpose();
  for (int n = 1; n < 4; ++n) G.noalias() += x[n] * r[n].transpose();
  return G;
}

}  // namespace taut
