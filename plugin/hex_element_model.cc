#include "plugin/hex_element_model.h"

namespace taut {

HexElementModel::HexElementModel(std::shared_ptr<const HexLattice> lattice,
                                 const Material& material, HexRotationMethod rotation_method)
    : lattice_(std::move(lattice)), rotation_method_(rotation_method) {
  TAUT_DEMAND(lattice_ != nullptr, "HexElementModel: lattice is null");
  ValidateHexLattice(*lattice_);
  material.Validate(lattice_->source);
  lame_ = {material.mu(), material.lambda()};
  rest_positions_.resize(3 * num_nodes());
  for (int i = 0; i < num_nodes(); ++i) rest_positions_.segment<3>(3 * i) = lattice_->nodes[i];
  rest_.reserve(num_elements());
  for (int e = 0; e < num_elements(); ++e)
    rest_.push_back(CalcHexRestElement(GatherElement(rest_positions_, e), lame_));
  rotations_.assign(num_elements(), Mat3::Identity());
}

HexNodes HexElementModel::GatherElement(const VecX& x, int e) const {
  const auto& h = lattice_->hexes[e];
  HexNodes xe;
  for (int a = 0; a < 8; ++a) xe[a] = x.segment<3>(3 * h[a]);
  return xe;
}

void HexElementModel::CalcLumpedMass(double density, VecX& mass) const {
  // Each hex gives an eighth of its mass rho V to each of its nodes.
  mass.setZero(num_nodes());
  for (int e = 0; e < num_elements(); ++e)
    for (int n : lattice_->hexes[e]) mass[n] += 0.125 * density * rest_[e].volume;
}

double HexElementModel::UpdateRotationsAndAddForces(const VecX& x, VecX& f) {
  double energy = 0.0;
  for (int e = 0; e < num_elements(); ++e) {
    // gather -> local (R, forces) -> scatter
    const HexNodes xe = GatherElement(x, e);
    rotations_[e] = CalcHexRotation(rest_[e], xe, rotation_method_);
    const Vec24 fe = CalcCorotatedHexForces(rest_[e], xe, rotations_[e]);
    energy += CalcCorotatedHexEnergy(rest_[e], xe, rotations_[e]);
    const auto& h = lattice_->hexes[e];
    for (int a = 0; a < 8; ++a) f.segment<3>(3 * h[a]) += fe.segment<3>(3 * a);
  }
  return energy;
}

void HexElementModel::AddScaledStiffness(double scale, const std::vector<int>& index_map,
                                         double* values) const {
  for (int e = 0; e < num_elements(); ++e) {
    const Mat3& R = rotations_[e];
    const int* map = index_map.data() + 576 * e;
    for (int a = 0; a < 8; ++a) {
      for (int b = 0; b < 8; ++b, map += 9) {
        // Block (a,b) of R K_e R^T, entries column-major.
        const Mat3 K = scale * (R * rest_[e].stiffness.block<3, 3>(3 * a, 3 * b) * R.transpose());
        for (int k = 0; k < 9; ++k)
          if (map[k] >= 0) values[map[k]] += K.data()[k];
      }
    }
  }
}

void HexElementModel::AddScaledStiffnessTimes(double scale, const VecX& v, VecX& out) const {
  for (int e = 0; e < num_elements(); ++e) {
    const Mat3& R = rotations_[e];
    const auto& h = lattice_->hexes[e];
    // out_e += scale R K_e R^T v_e.
    Vec24 w;
    for (int b = 0; b < 8; ++b) w.segment<3>(3 * b) = R.transpose() * v.segment<3>(3 * h[b]);
    const Vec24 Kw = rest_[e].stiffness * w;
    for (int a = 0; a < 8; ++a) out.segment<3>(3 * h[a]) += scale * (R * Kw.segment<3>(3 * a));
  }
}

double HexElementModel::CalcEnergy(const VecX& x) const {
  double energy = 0.0;
  for (int e = 0; e < num_elements(); ++e) {
    const HexNodes xe = GatherElement(x, e);
    const Mat3 R = CalcHexRotation(rest_[e], xe, rotation_method_);
    energy += CalcCorotatedHexEnergy(rest_[e], xe, R);
  }
  return energy;
}

}  // namespace taut
