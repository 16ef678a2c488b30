// What the implicit step needs from a body's elements (tets now, hexes later).
#pragma once

#include <vector>

#include "plugin/common.h"

namespace taut {

// The elastic elements of one body. One virtual call per body and stage, never per element;
// implementations loop over their elements with fixed-size kernels.
class ElementModel {
 public:
  virtual ~ElementModel() = default;

  // Number of nodes of the body.
  virtual int num_nodes() const = 0;
  // Number of elements.
  virtual int num_elements() const = 0;
  // Nodes per element (4 for tets, 8 for hexes).
  virtual int nodes_per_element() const = 0;
  // Node indices of element e (nodes_per_element() of them).
  virtual const int* element_nodes(int e) const = 0;
  // Rest positions (3 num_nodes, node-major xyz) [m].
  virtual const VecX& rest_positions() const = 0;
  // Rest volume of element e [m^3], > 0 (energy densities [J/m^3] times it give joules).
  virtual double element_rest_volume(int e) const = 0;
  // Lumped mass per node from the density [kg]; `mass` is resized to num_nodes().
  virtual void CalcLumpedMass(double density, VecX& mass) const = 0;

  // Updates the element rotations at x (3N) and adds the elastic forces into f (3N) [N].
  // Returns the elastic energy [J].
  virtual double UpdateRotationsAndAddForces(const VecX& x, VecX& f) = 0;
  // values[index_map[...]] += scale * K_e for every element with the frozen rotations of the last
  // update. index_map has nodes_per_element()^2 * 9 entries per element (block (a,b) row-major
  // blocks, entries column-major inside a block); -1 skips an entry.
  virtual void AddScaledStiffness(double scale, const std::vector<int>& index_map,
                                  double* values) const = 0;
  // out += scale * K v over all nodes, with the frozen rotations of the last update.
  virtual void AddScaledStiffnessTimes(double scale, const VecX& v, VecX& out) const = 0;
  // Elastic energy at x with rotations recomputed at x [J].
  virtual double CalcEnergy(const VecX& x) const = 0;
};

}  // namespace taut
