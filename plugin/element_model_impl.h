// The ElementModel overrides once for every element type: loops over the elements that gather
// an element's nodes, call the per-element kernels of `Traits` and scatter the results.
//
// `Traits` (tet_element_traits.h, hex_element_traits.h) supplies, for an element e of the body's
// rest data `data` (node positions x of the element, Nodes = std::array<Vec3, kNodes>):
//   kNodes                          nodes per element
//   Mesh, RestData, Frame           rest geometry; immutable rest data; what one rotation update
//                                   derives from x (at least the rotation R)
//   Elements(mesh)                  the node indices of every element
//   Volume(data, e)                 rest volume [m^3]
//   CalcFrame(data, e, x)           R of the element at x (and what the kernels reuse with it)
//   CalcEnergy(data, e, x, frame)   U_e [J];  CalcForces(data, e, x, frame): f_e = -dU_e/dx [N]
//   CalcForcesAndEnergy(data, e, x, frame, forces)  both at once: forces <- f_e, returns U_e
//   RestStiffnessBlock(data, e, a, b)   K0_ab [N/m];  MultiplyRestStiffness(data, e, w): K0 w
//   CalcFrozenStiffness(data, e, R)     R K0 R^T [N/m]
//   CalcRotatedStiffnessBlocks(data, e, R, scale, blocks)  blocks[kNodes a + b] = scale R K0_ab R^T
//   CalcDeformationGradient(data, e, x) dx/dX at the element centre
//   MakeContactSurface(mesh), MakeEmbeddedContactSurface(mesh, surface)
#pragma once

#include <algorithm>
#include <array>
#include <memory>
#include <utility>
#include <vector>

#include "plugin/contact_surface.h"
#include "plugin/element_model.h"

namespace taut {

template <typename Traits>
class ElementModelImpl : public ElementModel {
 public:
  static constexpr int kNodes = Traits::kNodes;
  using Mesh = typename Traits::Mesh;
  using RestData = typename Traits::RestData;
  using Nodes = std::array<Vec3, kNodes>;
  static_assert(kNodes <= kMaxElementNodes, "ElementVectors cannot hold the element's nodes");

  int num_nodes() const final { return static_cast<int>(mesh_->nodes.size()); }
  int num_elements() const final { return static_cast<int>(Traits::Elements(*mesh_).size()); }
  int nodes_per_element() const final { return kNodes; }
  const int* element_nodes(int e) const final { return Traits::Elements(*mesh_)[e].data(); }
  const VecX& rest_positions() const final { return rest_positions_; }
  double element_rest_volume(int e) const final { return Traits::Volume(data_, e); }
  void CalcLumpedMass(double density, VecX& mass) const final;

  double UpdateRotationsAndAddForces(const VecX& x, VecX& f) final;
  void AddHeldRotationForces(const VecX& x, VecX& f) const final;
  void AddScaledStiffness(double scale, const std::vector<int>& index_map,
                          double* values) const final;
  void AddScaledStiffnessTimes(double scale, const VecX& v, VecX& out) const final;
  double CalcEnergy(const VecX& x) const final;

  double CalcElementEnergy(int e, const VecX& x) const final;
  double CalcElementEnergyBound(int e, const VecX& x) const final {
    return Traits::CalcEnergyBound(data_, e, GatherElement(x, e));
  }
  double CalcElementForces(int e, const VecX& x, ElementVectors& forces) const final;
  double CalcElementForcesAndStiffnessAlong(int e, const VecX& x, ElementVectors& forces,
                                            double* f_K_f) const final;
  void CalcElementStiffness(int e, const VecX& x, ElementMatrix& K) const final;
  Mat3 CalcElementDeformationGradient(int e, const VecX& x) const final;
  Mat3 CalcElementRotation(int e, const VecX& x) const final;
  double CalcElementEnergyIn(int e, const VecX& x, const Mat3& R) const final;
  double CalcElementForcesAndStiffnessAlongIn(int e, const VecX& x, const Mat3& R,
                                              ElementVectors& forces, double* f_K_f) const final;
  void CalcElementStiffnessIn(int e, const Mat3& R, ElementMatrix& K) const final;

  ContactSurface MakeContactSurface() const final { return Traits::MakeContactSurface(*mesh_); }
  ContactSurface MakeEmbeddedContactSurface(const SurfaceMesh& surface) const final {
    return Traits::MakeEmbeddedContactSurface(*mesh_, surface);
  }

  // Rotation of element e from the last UpdateRotationsAndAddForces.
  const Mat3& rotation(int e) const { return rotations_[e]; }
  // Node positions of element e gathered from x (3N).
  Nodes GatherElement(const VecX& x, int e) const;

 protected:
  // `data` must have been computed from `mesh` (and validated it).
  ElementModelImpl(std::shared_ptr<const Mesh> mesh, RestData data);

  const Mesh& geometry() const { return *mesh_; }
  const RestData& rest_data() const { return data_; }

 private:
  // Elements per chunk of a split loop; loops over fewer than two chunks stay on one thread.
  static constexpr int kChunkElements = 32;
  bool SplitsLoops() const {
    return runner_ != nullptr && runner_->num_loop_threads() > 1 &&
           num_elements() >= 2 * kChunkElements;
  }
  int num_chunks() const { return (num_elements() + kChunkElements - 1) / kChunkElements; }
  // UpdateRotationsAndAddForces on the runner's threads: R, f_e and U_e per element into
  // rotations_, element_forces_ and element_energy_, then the serial loop's sums.
  double UpdateRotationsAndAddForcesSplit(const VecX& x, VecX& f);
  // AddScaledStiffness on the runner's threads, each adding the block rows of the nodes it owns
  // (RowOwners): a value of A (one row node) is added to by one thread, element by element in
  // the serial loop's order, so the sum is bitwise the serial one.
  void AddScaledStiffnessSplit(double scale, const std::vector<int>& index_map,
                               double* values) const;
  // Contiguous node ranges, one per loop thread, with about equal numbers of (element, node)
  // pairs, and the elements with a node in each range, in element order.
  struct RowOwners {
    std::vector<int> first_node;             // (parts + 1): part p owns [first_node[p], ...[p+1])
    std::vector<std::vector<int>> elements;  // (parts) elements touching part p's nodes
  };
  const RowOwners& RowOwnersFor(int parts) const;
  // The per-element kernel of UpdateRotationsAndAddForces: R_e at x into rotations_, f_e into
  // `forces`; returns U_e (gather -> local R, forces, energy).
  double UpdateElement(int e, const VecX& x, Nodes& forces);
  // The per-element kernel of AddScaledStiffness: the blocks of scale R_e K0_e R_e^T, block (a, b)
  // at kNodes a + b.
  using StiffnessBlocks = std::array<Mat3, kNodes * kNodes>;
  void CalcScaledStiffnessBlocks(int e, double scale, StiffnessBlocks& blocks) const {
    Traits::CalcRotatedStiffnessBlocks(data_, e, rotations_[e], scale, blocks);
  }
  // f(node of a) += forces[a] for the nodes of element e.
  void ScatterElement(int e, const Nodes& forces, VecX& f) const;

  std::shared_ptr<const Mesh> mesh_;
  RestData data_;
  VecX rest_positions_;
  std::vector<Mat3> rotations_;  // (num_elements)
  // Per-element results of the split loops (allocated on their first use).
  std::vector<Nodes> element_forces_;
  std::vector<double> element_energy_;
  mutable RowOwners row_owners_;  // RowOwnersFor, made on the first split assembly
};

template <typename Traits>
ElementModelImpl<Traits>::ElementModelImpl(std::shared_ptr<const Mesh> mesh, RestData data)
    : mesh_(std::move(mesh)), data_(std::move(data)) {
  rest_positions_.resize(3 * num_nodes());
  for (int i = 0; i < num_nodes(); ++i) rest_positions_.segment<3>(3 * i) = mesh_->nodes[i];
  rotations_.assign(num_elements(), Mat3::Identity());
}

template <typename Traits>
auto ElementModelImpl<Traits>::GatherElement(const VecX& x, int e) const -> Nodes {
  const auto& element = Traits::Elements(*mesh_)[e];
  Nodes xe;
  for (int a = 0; a < kNodes; ++a) xe[a] = x.template segment<3>(3 * element[a]);
  return xe;
}

template <typename Traits>
void ElementModelImpl<Traits>::ScatterElement(int e, const Nodes& forces, VecX& f) const {
  const auto& element = Traits::Elements(*mesh_)[e];
  for (int a = 0; a < kNodes; ++a) f.template segment<3>(3 * element[a]) += forces[a];
}

template <typename Traits>
void ElementModelImpl<Traits>::CalcLumpedMass(double density, VecX& mass) const {
  // Each element gives 1/kNodes of its mass rho V to each of its nodes.
  constexpr double kShare = 1.0 / kNodes;
  mass.setZero(num_nodes());
  for (int e = 0; e < num_elements(); ++e)
    for (int n : Traits::Elements(*mesh_)[e])
      mass[n] += kShare * density * Traits::Volume(data_, e);
}

template <typename Traits>
double ElementModelImpl<Traits>::UpdateRotationsAndAddForces(const VecX& x, VecX& f) {
  if (SplitsLoops()) return UpdateRotationsAndAddForcesSplit(x, f);
  double energy = 0.0;
  Nodes fe;
  for (int e = 0; e < num_elements(); ++e) {
    energy += UpdateElement(e, x, fe);
    ScatterElement(e, fe, f);
  }
  return energy;
}

template <typename Traits>
double ElementModelImpl<Traits>::UpdateElement(int e, const VecX& x, Nodes& forces) {
  const Nodes xe = GatherElement(x, e);
  const typename Traits::Frame frame = Traits::CalcFrame(data_, e, xe);
  rotations_[e] = frame.R;
  return Traits::CalcForcesAndEnergy(data_, e, xe, frame, forces);
}

template <typename Traits>
double ElementModelImpl<Traits>::UpdateRotationsAndAddForcesSplit(const VecX& x, VecX& f) {
  const int ne = num_elements();
  element_forces_.resize(ne);
  element_energy_.resize(ne);
  auto chunk = [&](int c) {
    const int end = std::min(ne, (c + 1) * kChunkElements);
    for (int e = c * kChunkElements; e < end; ++e)
      element_energy_[e] = UpdateElement(e, x, element_forces_[e]);
  };
  runner_->RunChunks(num_chunks(), chunk);
  // The serial loop's sum and scatter, in its order: bitwise its result.
  double energy = 0.0;
  for (int e = 0; e < ne; ++e) {
    energy += element_energy_[e];
    ScatterElement(e, element_forces_[e], f);
  }
  return energy;
}

template <typename Traits>
void ElementModelImpl<Traits>::AddHeldRotationForces(const VecX& x, VecX& f) const {
  for (int e = 0; e < num_elements(); ++e) {
    // f_e = -R K0 (R^T x_e - X_e).
    const Mat3& R = rotations_[e];
    const Nodes xe = GatherElement(x, e), X = GatherElement(rest_positions_, e);
    Nodes u;
    for (int b = 0; b < kNodes; ++b) u[b] = R.transpose() * xe[b] - X[b];
    const Nodes K0u = Traits::MultiplyRestStiffness(data_, e, u);
    Nodes fe;
    for (int a = 0; a < kNodes; ++a) fe[a] = -(R * K0u[a]);
    ScatterElement(e, fe, f);
  }
}

template <typename Traits>
void ElementModelImpl<Traits>::AddScaledStiffness(double scale, const std::vector<int>& index_map,
                                                  double* values) const {
  if (SplitsLoops()) return AddScaledStiffnessSplit(scale, index_map, values);
  constexpr int kEntries = 9 * kNodes * kNodes;
  StiffnessBlocks blocks;
  for (int e = 0; e < num_elements(); ++e) {
    const int* map = index_map.data() + kEntries * e;
    CalcScaledStiffnessBlocks(e, scale, blocks);
    for (const Mat3& K : blocks) {  // (a, b) row-major over blocks, entries column-major
      for (int k = 0; k < 9; ++k)
        if (map[k] >= 0) values[map[k]] += K.data()[k];
      map += 9;
    }
  }
}

template <typename Traits>
auto ElementModelImpl<Traits>::RowOwnersFor(int parts) const -> const RowOwners& {
  if (static_cast<int>(row_owners_.elements.size()) == parts) return row_owners_;
  const int nn = num_nodes(), ne = num_elements();
  std::vector<int> pairs_of_node(nn, 0);  // (element, node) pairs per node
  for (int e = 0; e < ne; ++e)
    for (int n : Traits::Elements(*mesh_)[e]) ++pairs_of_node[n];
  row_owners_.first_node.assign(1, 0);
  long long seen = 0;
  const long long total = static_cast<long long>(ne) * kNodes;
  for (int n = 0; n < nn && static_cast<int>(row_owners_.first_node.size()) < parts; ++n) {
    seen += pairs_of_node[n];
    if (seen * parts >= total * static_cast<long long>(row_owners_.first_node.size()))
      row_owners_.first_node.push_back(n + 1);
  }
  while (static_cast<int>(row_owners_.first_node.size()) <= parts)
    row_owners_.first_node.push_back(nn);
  row_owners_.elements.assign(parts, {});
  for (int p = 0; p < parts; ++p)
    for (int e = 0; e < ne; ++e)
      for (int n : Traits::Elements(*mesh_)[e])
        if (n >= row_owners_.first_node[p] && n < row_owners_.first_node[p + 1]) {
          row_owners_.elements[p].push_back(e);
          break;
        }
  return row_owners_;
}

template <typename Traits>
void ElementModelImpl<Traits>::AddScaledStiffnessSplit(double scale,
                                                       const std::vector<int>& index_map,
                                                       double* values) const {
  constexpr int kEntries = 9 * kNodes * kNodes;
  const RowOwners& owners = RowOwnersFor(runner_->num_loop_threads());
  auto part = [&](int p) {
    const int first = owners.first_node[p], last = owners.first_node[p + 1];
    StiffnessBlocks blocks;
    for (int e : owners.elements[p]) {
      CalcScaledStiffnessBlocks(e, scale, blocks);
      const auto& element = Traits::Elements(*mesh_)[e];
      for (int a = 0; a < kNodes; ++a) {
        if (element[a] < first || element[a] >= last) continue;  // another part's rows
        const int* map = index_map.data() + kEntries * e + 9 * kNodes * a;
        for (int b = 0; b < kNodes; ++b, map += 9) {
          const double* K = blocks[kNodes * a + b].data();
          for (int k = 0; k < 9; ++k)
            if (map[k] >= 0) values[map[k]] += K[k];
        }
      }
    }
  };
  runner_->RunChunks(static_cast<int>(owners.elements.size()), part);
}

template <typename Traits>
void ElementModelImpl<Traits>::AddScaledStiffnessTimes(double scale, const VecX& v,
                                                       VecX& out) const {
  for (int e = 0; e < num_elements(); ++e) {
    // out_e += scale R K0 R^T v_e.
    const Mat3& R = rotations_[e];
    const auto& element = Traits::Elements(*mesh_)[e];
    Nodes w;
    for (int b = 0; b < kNodes; ++b) w[b] = R.transpose() * v.template segment<3>(3 * element[b]);
    const Nodes K0w = Traits::MultiplyRestStiffness(data_, e, w);
    for (int a = 0; a < kNodes; ++a)
      out.template segment<3>(3 * element[a]) += scale * (R * K0w[a]);
  }
}

template <typename Traits>
double ElementModelImpl<Traits>::CalcEnergy(const VecX& x) const {
  double energy = 0.0;
  for (int e = 0; e < num_elements(); ++e) energy += CalcElementEnergy(e, x);
  return energy;
}

template <typename Traits>
double ElementModelImpl<Traits>::CalcElementEnergy(int e, const VecX& x) const {
  return CalcElementEnergyIn(e, x, CalcElementRotation(e, x));
}

template <typename Traits>
double ElementModelImpl<Traits>::CalcElementForces(int e, const VecX& x,
                                                   ElementVectors& forces) const {
  return CalcElementForcesAndStiffnessAlong(e, x, forces, nullptr);
}

template <typename Traits>
double ElementModelImpl<Traits>::CalcElementForcesAndStiffnessAlong(int e, const VecX& x,
                                                                    ElementVectors& forces,
                                                                    double* f_K_f) const {
  return CalcElementForcesAndStiffnessAlongIn(e, x, CalcElementRotation(e, x), forces, f_K_f);
}

template <typename Traits>
void ElementModelImpl<Traits>::CalcElementStiffness(int e, const VecX& x, ElementMatrix& K) const {
  CalcElementStiffnessIn(e, CalcElementRotation(e, x), K);
}

template <typename Traits>
Mat3 ElementModelImpl<Traits>::CalcElementRotation(int e, const VecX& x) const {
  return Traits::CalcFrame(data_, e, GatherElement(x, e)).R;
}

template <typename Traits>
double ElementModelImpl<Traits>::CalcElementEnergyIn(int e, const VecX& x, const Mat3& R) const {
  const Nodes xe = GatherElement(x, e);
  return Traits::CalcEnergy(data_, e, xe, Traits::MakeFrame(data_, e, xe, R));
}

template <typename Traits>
double ElementModelImpl<Traits>::CalcElementForcesAndStiffnessAlongIn(int e, const VecX& x,
                                                                      const Mat3& R,
                                                                      ElementVectors& forces,
                                                                      double* f_K_f) const {
  const Nodes xe = GatherElement(x, e);
  const typename Traits::Frame frame = Traits::MakeFrame(data_, e, xe, R);
  Nodes fe;
  const double energy = Traits::CalcForcesAndEnergy(data_, e, xe, frame, fe);
  for (int a = 0; a < kNodes; ++a) forces[a] = fe[a];
  if (f_K_f != nullptr) {
    // f^T R K0 R^T f = w^T K0 w with w_a = R^T f_a (K0 stored at rest).
    Nodes w;
    for (int a = 0; a < kNodes; ++a) w[a] = R.transpose() * fe[a];
    const Nodes K0w = Traits::MultiplyRestStiffness(data_, e, w);
    double sum = 0.0;
    for (int a = 0; a < kNodes; ++a) sum += w[a].dot(K0w[a]);
    *f_K_f = sum;
  }
  return energy;
}

template <typename Traits>
void ElementModelImpl<Traits>::CalcElementStiffnessIn(int e, const Mat3& R,
                                                      ElementMatrix& K) const {
  K = Traits::CalcFrozenStiffness(data_, e, R);
}

template <typename Traits>
Mat3 ElementModelImpl<Traits>::CalcElementDeformationGradient(int e, const VecX& x) const {
  return Traits::CalcDeformationGradient(data_, e, GatherElement(x, e));
}

}  // namespace taut
