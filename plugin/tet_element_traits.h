// The per-element kernels of co-rotated linear tets (corotated_tet_element.h) in the form
// ElementModelImpl (element_model_impl.h) calls them.
#pragma once

#include <array>
#include <vector>

#include "plugin/contact_surface.h"
#include "plugin/corotated_tet_element.h"
#include "plugin/material.h"
#include "plugin/polar_rotation.h"

namespace taut {

// Rest stiffness K0 of one tet as its 16 3x3 blocks, block (n,m) = CalcRestStiffnessBlock(n, m)
// at index 4 n + m (1152 bytes) [N/m].
using TetRestStiffness = std::array<Mat3, 16>;

// The 16 blocks K0_nm of one tet, each exactly as CalcRestStiffnessBlock computes it.
TetRestStiffness CalcTetRestStiffness(const TetRestElement& rest, const LameParameters& lame);

// blocks[4 n + m] = scale R K0_nm R^T of one tet. With q_n = R r_n and R R^T = I the rest block
// V (lambda r_n r_m^T + mu r_m r_n^T + mu (r_n . r_m) I) (CalcRestStiffnessBlock) rotates to
// V (lambda q_n q_m^T + mu q_m q_n^T + mu (r_n . r_m) I); block (m, n) is block (n, m)^T.
void CalcRotatedTetStiffnessBlocks(const TetRestElement& rest, const LameParameters& lame,
                                   const Mat3& R, double scale, TetRestStiffness& blocks);

struct TetElementTraits {
  static constexpr int kNodes = 4;
  using Mesh = TetMesh;
  using Nodes = std::array<Vec3, 4>;

  // Immutable rest data of a tet body with one material.
  struct RestData {
    TetRestData rest;                         // r_n and V of every tet
    std::vector<TetRestStiffness> stiffness;  // K0 of every tet, from rest and lame
    LameParameters lame;
  };
  // G = sum_n x_n r_n^T and its rotation R = polar(G).
  struct Frame {
    Mat3 G;
    Mat3 R;
  };

  // Validates the material, then the mesh (throws InputError naming mesh.source), and computes
  // r_n, V and K0 of every tet.
  static RestData CalcRestData(const TetMesh& mesh, const Material& material);

  static const std::vector<std::array<int, 4>>& Elements(const TetMesh& mesh) { return mesh.tets; }
  static double Volume(const RestData& data, int e) { return data.rest.elements[e].volume; }

  static Frame CalcFrame(const RestData& data, int e, const Nodes& x) {
    const Mat3 G = CalcTetDeformationGradient(data.rest.elements[e], x);
    return {G, CalcPolarRotation(G)};
  }
  // The frame at x with R computed before (CalcFrame's R at the same x).
  static Frame MakeFrame(const RestData& data, int e, const Nodes& x, const Mat3& R) {
    return {CalcTetDeformationGradient(data.rest.elements[e], x), R};
  }
  // An upper bound on CalcEnergy's Psi without R (+inf for an inverted element).
  static double CalcEnergyBound(const RestData& data, int e, const Nodes& x) {
    const TetRestElement& rest = data.rest.elements[e];
    return CalcCorotatedTetEnergyBound(rest, data.lame, CalcTetDeformationGradient(rest, x));
  }
  // Psi = V [mu ||S - I||^2 + lambda/2 tr(S - I)^2], S = R^T G.
  static double CalcEnergy(const RestData& data, int e, const Nodes& /*x*/, const Frame& frame) {
    return CalcCorotatedTetEnergy(data.rest.elements[e], data.lame, frame.G, frame.R);
  }
  // f_n = -V P r_n, the exact -dPsi/dx_n.
  static Nodes CalcForces(const RestData& data, int e, const Nodes& /*x*/, const Frame& frame) {
    return CalcCorotatedTetForces(data.rest.elements[e], data.lame, frame.G, frame.R);
  }
  // Both: forces <- f, returns Psi.
  static double CalcForcesAndEnergy(const RestData& data, int e, const Nodes& x, const Frame& frame,
                                    Nodes& forces) {
    forces = CalcForces(data, e, x, frame);
    return CalcEnergy(data, e, x, frame);
  }

  static const Mat3& RestStiffnessBlock(const RestData& data, int e, int a, int b) {
    return data.stiffness[e][4 * a + b];
  }
  // blocks[4 n + m] = scale R K0_nm R^T (CalcRotatedTetStiffnessBlocks: K0's closed form with
  // rotated shape gradients, about a quarter of the products of R K0_nm R^T).
  static void CalcRotatedStiffnessBlocks(const RestData& data, int e, const Mat3& R, double scale,
                                         TetRestStiffness& blocks) {
    CalcRotatedTetStiffnessBlocks(data.rest.elements[e], data.lame, R, scale, blocks);
  }
  // (K0 w)_a = sum_b K0_ab w_b.
  static Nodes MultiplyRestStiffness(const RestData& data, int e, const Nodes& w) {
    const TetRestStiffness& K0 = data.stiffness[e];
    Nodes K0w;
    for (int a = 0; a < 4; ++a) {
      Vec3 sum = Vec3::Zero();
      for (int b = 0; b < 4; ++b) sum += K0[4 * a + b] * w[b];
      K0w[a] = sum;
    }
    return K0w;
  }
  static Mat12 CalcFrozenStiffness(const RestData& data, int e, const Mat3& R) {
    return CalcFrozenRotationTetStiffness(data.rest.elements[e], data.lame, R);
  }
  static Mat3 CalcDeformationGradient(const RestData& data, int e, const Nodes& x) {
    return CalcTetDeformationGradient(data.rest.elements[e], x);
  }

  // Boundary vertices and faces.
  static ContactSurface MakeContactSurface(const TetMesh& mesh) {
    return MakeTetContactSurface(mesh);
  }
  // 4-node barycentric points (EmbedSurfaceInTets).
  static ContactSurface MakeEmbeddedContactSurface(const TetMesh& mesh,
                                                   const SurfaceMesh& surface) {
    return MakeTetEmbeddedContactSurface(mesh, EmbedSurfaceInTets(mesh, surface));
  }
};

}  // namespace taut
