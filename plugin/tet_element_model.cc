#include "plugin/tet_element_model.h"

#include "plugin/signed_svd.h"

namespace taut {

TetRestStiffness CalcTetRestStiffness(const TetRestElement& rest, const LameParameters& lame) {
  TetRestStiffness K0;
  for (int n = 0; n < 4; ++n)
    for (int m = 0; m < 4; ++m) K0[4 * n + m] = CalcRestStiffnessBlock(rest, lame, n, m);
  return K0;
}

TetElementModel::TetElementModel(std::shared_ptr<const TetMesh> mesh, const Material& material)
    : mesh_(std::move(mesh)) {
  TAUT_DEMAND(mesh_ != nullptr, "TetElementModel: mesh is null");
  material.Validate(mesh_->source);
  rest_ = CalcTetRestData(*mesh_);
  lame_ = {material.mu(), material.lambda()};
  // K0 depends only on the rest shape and the material, both fixed from here on.
  rest_stiffness_.reserve(num_elements());
  for (const TetRestElement& rest : rest_.elements)
    rest_stiffness_.push_back(CalcTetRestStiffness(rest, lame_));
  rest_positions_.resize(3 * num_nodes());
  for (int i = 0; i < num_nodes(); ++i) rest_positions_.segment<3>(3 * i) = mesh_->nodes[i];
  rotations_.assign(num_elements(), Mat3::Identity());
}

std::array<Vec3, 4> TetElementModel::GatherElement(const VecX& x, int e) const {
  const auto& t = mesh_->tets[e];
  return {x.segment<3>(3 * t[0]), x.segment<3>(3 * t[1]), x.segment<3>(3 * t[2]),
          x.segment<3>(3 * t[3])};
}

void TetElementModel::CalcLumpedMass(double density, VecX& mass) const {
  // Each tet gives a quarter of its mass rho V to each of its nodes.
  mass.setZero(num_nodes());
  for (int e = 0; e < num_elements(); ++e)
    for (int n : mesh_->tets[e]) mass[n] += 0.25 * density * rest_.elements[e].volume;
}

double TetElementModel::UpdateRotationsAndAddForces(const VecX& x, VecX& f) {
  double energy = 0.0;
  for (int e = 0; e < num_elements(); ++e) {
    // gather -> local (G, R, forces) -> scatter
    const auto xe = GatherElement(x, e);
    const TetRestElement& rest = rest_.elements[e];
    const Mat3 G = CalcTetDeformationGradient(rest, xe);
    rotations_[e] = CalcPolarRotation(G);
    const auto fe = CalcCorotatedTetForces(rest, lame_, G, rotations_[e]);
    energy += CalcCorotatedTetEnergy(rest, lame_, G, rotations_[e]);
    const auto& t = mesh_->tets[e];
    for (int n = 0; n < 4; ++n) f.segment<3>(3 * t[n]) += fe[n];
  }
  return energy;
}

void TetElementModel::AddScaledStiffness(double scale, const std::vector<int>& index_map,
                                         double* values) const {
  for (int e = 0; e < num_elements(); ++e) {
    const Mat3& R = rotations_[e];
    const TetRestStiffness& K0 = rest_stiffness_[e];
    const int* map = index_map.data() + 144 * e;
    for (int a = 0; a < 4; ++a) {
      for (int b = 0; b < 4; ++b, map += 9) {
        // Block (a,b) of R K0 R^T, entries column-major.
        const Mat3 K = scale * (R * K0[4 * a + b] * R.transpose());
        for (int k = 0; k < 9; ++k)
          if (map[k] >= 0) values[map[k]] += K.data()[k];
      }
    }
  }
}

void TetElementModel::AddScaledStiffnessTimes(double scale, const VecX& v, VecX& out) const {
  for (int e = 0; e < num_elements(); ++e) {
    const Mat3& R = rotations_[e];
    const TetRestStiffness& K0 = rest_stiffness_[e];
    const auto& t = mesh_->tets[e];
    for (int a = 0; a < 4; ++a) {
      // out_a += scale R sum_b K0_ab R^T v_b.
      Vec3 sum = Vec3::Zero();
      for (int b = 0; b < 4; ++b) sum += K0[4 * a + b] * (R.transpose() * v.segment<3>(3 * t[b]));
      out.segment<3>(3 * t[a]) += scale * (R * sum);
    }
  }
}

double TetElementModel::CalcEnergy(const VecX& x) const {
  double energy = 0.0;
  for (int e = 0; e < num_elements(); ++e) {
    const Mat3 G = CalcTetDeformationGradient(rest_.elements[e], GatherElement(x, e));
    energy += CalcCorotatedTetEnergy(rest_.elements[e], lame_, G, CalcPolarRotation(G));
  }
  return energy;
}

}  // namespace taut
