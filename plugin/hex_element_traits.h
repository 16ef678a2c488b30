// The per-element kernels of co-rotated trilinear hexes (corotated_hex_element.h) in the form
// ElementModelImpl (element_model_impl.h) calls them.
#pragma once

#include <array>
#include <vector>

#include "plugin/contact_surface.h"
#include "plugin/corotated_hex_element.h"
#include "plugin/dense_kernels.h"
#include "plugin/material.h"

namespace taut {

struct HexElementTraits {
  static constexpr int kNodes = 8;
  using Mesh = HexLattice;
  using Nodes = HexNodes;

  // Immutable rest data of a hex body with one material.
  struct RestData {
    std::vector<HexRestElement> elements;  // gradients, weights and K_e of every hex
    LameParameters lame;
    HexRotationMethod rotation_method = HexRotationMethod::kCenterPolar;
  };
  // The element rotation R (by data.rotation_method).
  struct Frame {
    Mat3 R;
  };

  // Validates the lattice, then the material (throws InputError naming lattice.source), and
  // computes the rest data of every hex.
  static RestData CalcRestData(const HexLattice& lattice, const Material& material,
                               HexRotationMethod rotation_method);

  static const std::vector<std::array<int, 8>>& Elements(const HexLattice& lattice) {
    return lattice.hexes;
  }
  static double Volume(const RestData& data, int e) { return data.elements[e].volume; }

  static Frame CalcFrame(const RestData& data, int e, const Nodes& x) {
    return {CalcHexRotation(data.elements[e], x, data.rotation_method)};
  }
  // The frame at x with R computed before (CalcFrame's R at the same x).
  static Frame MakeFrame(const RestData& /*data*/, int /*e*/, const Nodes& /*x*/, const Mat3& R) {
    return {R};
  }
  // An upper bound on CalcEnergy's U without R (+inf for an inverted element).
  static double CalcEnergyBound(const RestData& data, int e, const Nodes& x) {
    const HexRestElement& rest = data.elements[e];
    return CalcCorotatedHexEnergyBound(rest, x,
                                       CalcHexRotationGradient(rest, x, data.rotation_method));
  }
  // U = 1/2 (R^T x - X)^T K_e (R^T x - X).
  static double CalcEnergy(const RestData& data, int e, const Nodes& x, const Frame& frame) {
    return CalcCorotatedHexEnergy(data.elements[e], x, frame.R);
  }
  // Both from one product K_e u: forces <- f, returns U.
  static double CalcForcesAndEnergy(const RestData& data, int e, const Nodes& x, const Frame& frame,
                                    Nodes& forces) {
    Vec24 f;
    const double energy = CalcCorotatedHexForcesAndEnergy(data.elements[e], x, frame.R, f);
    for (int a = 0; a < 8; ++a) forces[a] = f.segment<3>(3 * a);
    return energy;
  }
  // f = -R K_e (R^T x - X).
  static Nodes CalcForces(const RestData& data, int e, const Nodes& x, const Frame& frame) {
    const Vec24 f = CalcCorotatedHexForces(data.elements[e], x, frame.R);
    Nodes forces;
    for (int a = 0; a < 8; ++a) forces[a] = f.segment<3>(3 * a);
    return forces;
  }

  static auto RestStiffnessBlock(const RestData& data, int e, int a, int b) {
    return data.elements[e].stiffness().block<3, 3>(3 * a, 3 * b);
  }
  // blocks[8 a + b] = scale R K0_ab R^T (the upper blocks, the lower ones by symmetry).
  static void CalcRotatedStiffnessBlocks(const RestData& data, int e, const Mat3& R, double scale,
                                         HexStiffnessBlocks& blocks) {
    CalcRotatedHexStiffnessBlocks(data.elements[e], R, scale, blocks);
  }
  // K_e w, w node-major.
  static Nodes MultiplyRestStiffness(const RestData& data, int e, const Nodes& w) {
    Vec24 packed;
    for (int b = 0; b < 8; ++b) packed.segment<3>(3 * b) = w[b];
    Vec24 Kw;
    ActiveDenseKernels().multiply_hex_stiffness(data.elements[e].stiffness().data(), packed.data(),
                                                Kw.data());
    Nodes K0w;
    for (int a = 0; a < 8; ++a) K0w[a] = Kw.segment<3>(3 * a);
    return K0w;
  }
  static Mat24 CalcFrozenStiffness(const RestData& data, int e, const Mat3& R) {
    return CalcFrozenRotationHexStiffness(data.elements[e], R);
  }
  // G(0) at the element centre.
  static Mat3 CalcDeformationGradient(const RestData& data, int e, const Nodes& x) {
    return CalcHexCenterDeformationGradient(data.elements[e], x);
  }

  // Boundary corners and faces (two triangles per boundary quad).
  static ContactSurface MakeContactSurface(const HexLattice& lattice) {
    return MakeHexContactSurface(lattice);
  }
  // 8-node trilinear points (EmbedSurface).
  static ContactSurface MakeEmbeddedContactSurface(const HexLattice& lattice,
                                                   const SurfaceMesh& surface) {
    return taut::MakeEmbeddedContactSurface(lattice, EmbedSurface(lattice, surface));
  }
};

}  // namespace taut
