// What the implicit step, the constraints and the contact code need from a body's elements, in
// terms of no particular element type (tets, hexes).
#pragma once

#include <array>
#include <vector>

#include "plugin/common.h"
#include "plugin/element_loop_runner.h"

namespace taut {

struct ContactSurface;
struct HexLattice;
struct SurfaceMesh;
struct TetMesh;
class TetElementModel;

// Most nodes one element has (a hex).
inline constexpr int kMaxElementNodes = 8;
// Per-node vectors of one element (the first nodes_per_element() entries are used).
using ElementVectors = std::array<Vec3, kMaxElementNodes>;
// A matrix over one element's 3 nodes_per_element() coordinates, node-major xyz, stored in place
// (no heap allocation).
using ElementMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor,
                                    3 * kMaxElementNodes, 3 * kMaxElementNodes>;

// The elastic elements of one body. Every element e has a rotation R_e (its co-rotated frame) and
// the energy U_e = 1/2 u^T K0_e u of u = R_e^T x_e - X_e (X_e its rest nodes), so with R_e held
//   f_e = -dU_e/dx = -R_e K0_e (R_e^T x_e - X_e),   K_e = -df_e/dx = R_e K0_e R_e^T.
// Whole-body calls are one virtual call per body and stage, never per element; implementations
// loop over their elements with fixed-size kernels (element_model_impl.h).
class ElementModel {
 public:
  virtual ~ElementModel() = default;

  // Threads that split the element loops of UpdateRotationsAndAddForces and AddScaledStiffness
  // (null: the calling thread alone). The results are bitwise the same for any runner: elements
  // are computed on any thread into their own slots, then summed and scattered in element order.
  void set_loop_runner(ElementLoopRunner* runner) { runner_ = runner; }

  // Number of nodes of the body.
  virtual int num_nodes() const = 0;
  // Number of elements.
  virtual int num_elements() const = 0;
  // Nodes per element (4 for tets, 8 for hexes), at most kMaxElementNodes.
  virtual int nodes_per_element() const = 0;
  // Node indices of element e (nodes_per_element() of them).
  virtual const int* element_nodes(int e) const = 0;
  // Rest positions (3 num_nodes, node-major xyz) [m].
  virtual const VecX& rest_positions() const = 0;
  // Rest volume of element e [m^3], > 0 (energy densities [J/m^3] times it give joules).
  virtual double element_rest_volume(int e) const = 0;
  // Lumped mass per node from the density [kg]; `mass` is resized to num_nodes().
  virtual void CalcLumpedMass(double density, VecX& mass) const = 0;

  // --- Whole body ---
  // Updates the element rotations at x (3N) and adds the elastic forces into f (3N) [N].
  // Returns the elastic energy [J].
  virtual double UpdateRotationsAndAddForces(const VecX& x, VecX& f) = 0;
  // f += -R K0 (R^T x - X) of every element at x (3N) with the rotations of the last update held
  // [N]: the force whose Jacobian is -K of AddScaledStiffness(Times); at the update's x it is the
  // force UpdateRotationsAndAddForces added.
  virtual void AddHeldRotationForces(const VecX& x, VecX& f) const = 0;
  // values[index_map[...]] += scale * K_e for every element with the frozen rotations of the last
  // update. index_map has nodes_per_element()^2 * 9 entries per element (block (a,b) row-major
  // blocks, entries column-major inside a block); -1 skips an entry.
  virtual void AddScaledStiffness(double scale, const std::vector<int>& index_map,
                                  double* values) const = 0;
  // out += scale * K v over all nodes, with the frozen rotations of the last update.
  virtual void AddScaledStiffnessTimes(double scale, const VecX& v, VecX& out) const = 0;
  // Elastic energy at x with rotations recomputed at x [J].
  virtual double CalcEnergy(const VecX& x) const = 0;

  // --- One element e at body positions x (3N), its rotation R_e recomputed at x ---
  // U_e [J].
  virtual double CalcElementEnergy(int e, const VecX& x) const = 0;
  // An upper bound on U_e without the polar decomposition (docs/math.md §4.6), to skip elements
  // far below a limit; +inf for an inverted element [J].
  virtual double CalcElementEnergyBound(int e, const VecX& x) const = 0;
  // Returns U_e [J] and sets forces[a] = f_e of node element_nodes(e)[a] [N] (R_e held).
  virtual double CalcElementForces(int e, const VecX& x, ElementVectors& forces) const = 0;
  // The same, and (f_K_f not null) *f_K_f = f_e^T K f_e with K = R_e K0_e R_e^T
  // (CalcElementStiffness) from the same R_e: the stiffness along the forces (an energy-limit
  // row's curvature along its Jacobian).
  virtual double CalcElementForcesAndStiffnessAlong(int e, const VecX& x, ElementVectors& forces,
                                                    double* f_K_f) const = 0;
  // K = R_e K0_e R_e^T (3n x 3n for n = nodes_per_element(), symmetric PSD) [N/m].
  virtual void CalcElementStiffness(int e, const VecX& x, ElementMatrix& K) const = 0;
  // Deformation gradient dx/dX at the element centre (constant over a tet) [-].
  virtual Mat3 CalcElementDeformationGradient(int e, const VecX& x) const = 0;

  // --- The same with R_e given: for callers that evaluate one element several times at the same
  // x (energy-limit rows: energy, then forces, then stiffness), R_e from CalcElementRotation at
  // that x, so its polar decomposition runs once. Results are bit for bit the calls above. ---
  // R_e at x (the element's corotated frame).
  virtual Mat3 CalcElementRotation(int e, const VecX& x) const = 0;
  virtual double CalcElementEnergyIn(int e, const VecX& x, const Mat3& R) const = 0;
  virtual double CalcElementForcesAndStiffnessAlongIn(int e, const VecX& x, const Mat3& R,
                                                      ElementVectors& forces,
                                                      double* f_K_f) const = 0;
  virtual void CalcElementStiffnessIn(int e, const Mat3& R, ElementMatrix& K) const = 0;

  // --- Contact ---
  // The body's boundary as contact points (its boundary nodes) and outward triangles.
  virtual ContactSurface MakeContactSurface() const = 0;
  // `surface` (in the rest frame) embedded in the elements: one point per vertex, a weighted
  // combination of the nodes of the element holding it. Throws InputError when a vertex lies in
  // no element.
  virtual ContactSurface MakeEmbeddedContactSurface(const SurfaceMesh& surface) const = 0;

  // --- The concrete geometry, only for callers that need it (writers, tet-only limits) ---
  // The rest tet mesh of a tet model, else null.
  virtual const TetMesh* tet_mesh() const { return nullptr; }
  // The rest hex lattice of a hex model, else null.
  virtual const HexLattice* hex_lattice() const { return nullptr; }
  // The model itself when it is made of co-rotated tets (its rest data r_n), else null.
  virtual const TetElementModel* tet_model() const { return nullptr; }

 protected:
  ElementLoopRunner* runner_ = nullptr;
};

}  // namespace taut
