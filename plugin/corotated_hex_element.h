// Co-rotational linear elasticity on one trilinear hexahedron (paper B with the fixes of
// docs/math.md §4 and §6 B1-B3).
//
// With h_qa = (H(s_q) F_q^-1)_a the gradient of N_a w.r.t. the rest coordinates at Gauss point q
// (F_q = dX/ds there, 2x2x2 rule, weights 1) and u = R^T x - X (24), the element energy is
//   U = 1/2 u^T K_e u = sum_q det F_q psi(eps_q),  eps_q = sym(R^T G_q) - I,
//   G_q = sum_a x_a h_qa^T,  psi = mu eps:eps + (lambda/2) tr(eps)^2 = 1/2 eps:C:eps,
// with K_e = sum_q det F_q B_q^T C B_q (24x24). With R frozen, f = -dU/dx = -R K_e u and
// -df/dx = R K_e R^T (block diag R). R is the signed polar rotation of G(0), the deformation
// gradient at the element centre, or (to reproduce the paper) of the inscribed tet {1,4,6,7}.
// Local node a = paper node n - 1, reference corner HexCornerSign(a) (hex_lattice.h).
#pragma once

#include <array>
#include <memory>
#include <vector>

#include "plugin/corotated_tet_element.h"
#include "plugin/hex_lattice.h"

namespace taut {

using Vec24 = Eigen::Matrix<double, 24, 1>;
using Mat24 = Eigen::Matrix<double, 24, 24>;
using HexNodes = std::array<Vec3, 8>;
using HexGradients = Eigen::Matrix<double, 8, 3>;  // row a = gradient of N_a [1/m]

// How the element rotation is taken (docs/math.md §4.4).
enum class HexRotationMethod {
  kCenterPolar,   // R = polar(G(0)): no spurious rotation under bending modes (recommended)
  kInscribedTet,  // R = polar(G_{1467}) of the inscribed tet (paper B; aliases bending)
};

// Rest data of one hex, computed once.
struct HexRestElement {
  HexNodes X;                             // rest node positions [m]
  std::array<HexGradients, 8> gradients;  // H(s_q) F_q^-1 at Gauss point q [1/m]
  std::array<double, 8> weights;          // w_q det F_q, w_q = 1 [m^3]
  HexGradients center_gradients;          // H(0) F(0)^-1 [1/m]
  // [X_b - X_a, X_c - X_a, X_d - X_a]^-1 of the inscribed tets {1,4,6,7} and {2,3,5,8} [1/m].
  std::array<Mat3, 2> tet_rest_inverses;
  double volume = 0.0;  // sum_q w_q det F_q [m^3]
  // K_e, node-major xyz [N/m]; one matrix for the elements that ShareEqualHexStiffnesses found
  // equal (a lattice's cells: the step streams one K_e instead of 4.6 kB per element).
  std::shared_ptr<const Mat24> shared_stiffness;
  const Mat24& stiffness() const { return *shared_stiffness; }
  // max_i sum_j |K_e,ij| (1 + 1e-7) >= lambda_max(K_e), also of a shared K_e (within 1e-9 of
  // its own entrywise) [N/m].
  double stiffness_norm_bound = 0.0;
};

// Local nodes (0-based) of the inscribed tets: {1,4,6,7} -> {0,3,5,6}, {2,3,5,8} -> {1,2,4,7}.
inline constexpr int kHexInscribedTets[2][4] = {{0, 3, 5, 6}, {1, 2, 4, 7}};

// Precomputes gradients, weights and K_e of a hex with rest nodes X (throws InputError if
// det F_q <= 0 at a Gauss point).
HexRestElement CalcHexRestElement(const HexNodes& X, const LameParameters& lame);

// Elements whose K_e agree within kSharedHexStiffnessTolerance max|K_e| in every entry point to
// the first such element's K_e. Equal cells of a lattice differ in X_a - X_0 by the rounding of
// X, ulp(|X|) / edge relative (2e-12 for 0.1 m cells 1 km from the origin), and their K_e as
// much; the tolerance is a rest shape moved by 1e-9 of its size. Elements keep their own
// gradients and rest positions.
inline constexpr double kSharedHexStiffnessTolerance = 1e-9;
void ShareEqualHexStiffnesses(std::vector<HexRestElement>& elements);

// G = sum_a x_a g_a^T for gradients g (one row per node).
Mat3 CalcHexDeformationGradient(const HexGradients& g, const HexNodes& x);

// G(0) at the element centre, = 1/2 (G_1467 + G_2358) when the rest hex is a parallelepiped.
Mat3 CalcHexCenterDeformationGradient(const HexRestElement& rest, const HexNodes& x);

// Affine deformation gradient of inscribed tet t (0: {1,4,6,7}, 1: {2,3,5,8}).
Mat3 CalcHexInscribedTetDeformationGradient(const HexRestElement& rest, const HexNodes& x, int t);

// The deformation gradient whose polar factor is the element rotation: G(0) or G_1467.
Mat3 CalcHexRotationGradient(const HexRestElement& rest, const HexNodes& x,
                             HexRotationMethod method);

// Element rotation: signed polar rotation of G(0) or of G_1467 (det R = +1 even when inverted).
Mat3 CalcHexRotation(const HexRestElement& rest, const HexNodes& x, HexRotationMethod method);

// Co-rotated strain at Gauss point q: eps_q = sym(R^T G_q) - I.
Mat3 CalcHexGaussStrain(const HexRestElement& rest, const HexNodes& x, const Mat3& R, int q);

// An upper bound on U without R, for R = polar(G) (docs/math.md §4.6): with u_a = R^T (x_a -
// x_c) - (X_a - X_c), ||u_a|| <= ||(x_a - x_c) - G (X_a - X_c)|| + ||G^T G - I||_F ||X_a - X_c||
// for det G > 0, and U <= 1/2 lambda_max(K_e) ||u||^2; +inf for det G <= 0 [J].
double CalcCorotatedHexEnergyBound(const HexRestElement& rest, const HexNodes& x, const Mat3& G);

// U = 1/2 (R^T x - X)^T K_e (R^T x - X) [J].
double CalcCorotatedHexEnergy(const HexRestElement& rest, const HexNodes& x, const Mat3& R);

// f = -R K_e (R^T x - X), node-major [N] (= -dU/dx with R frozen).
Vec24 CalcCorotatedHexForces(const HexRestElement& rest, const HexNodes& x, const Mat3& R);

// Both of the above from one product K_e u: forces <- f, returns U (the same bits as the two
// calls).
double CalcCorotatedHexForcesAndEnergy(const HexRestElement& rest, const HexNodes& x, const Mat3& R,
                                       Vec24& forces);

// 3x3 blocks of the rotated stiffness, (a, b) at 8 a + b.
using HexStiffnessBlocks = std::array<Mat3, 64>;
// blocks[8 a + b] = scale R K_ab R^T. K_e is symmetric (K_ba = K_ab^T exactly, CalcHexRestElement),
// so the 28 blocks below the diagonal are the transposes of those above it: 36 products of three
// 3x3 matrices instead of 64.
void CalcRotatedHexStiffnessBlocks(const HexRestElement& rest, const Mat3& R, double scale,
                                   HexStiffnessBlocks& blocks);

// Frozen-rotation stiffness R K_e R^T (= -df/dx with R frozen), symmetric PSD [N/m].
Mat24 CalcFrozenRotationHexStiffness(const HexRestElement& rest, const Mat3& R);

}  // namespace taut
