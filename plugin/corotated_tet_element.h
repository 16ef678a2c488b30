// Co-rotational linear elasticity on one linear tetrahedron.
//
// With R the rotation of the signed polar decomposition G = R S (S = R^T G symmetric, also for
// inverted elements: docs/math.md §0.2), the strain is eps = S - I and the energy
//   Psi = V [ mu ||S - I||_F^2 + (lambda/2) tr(S - I)^2 ]                       [J]
// Its first Piola stress is P = 2 mu (G - R) + lambda tr(S - I) R, exact because the dR terms
// vanish (S - I symmetric, R^T dR skew). Nodal forces f_n = -V P r_n equal -dPsi/dx_n, i.e. the
// warped force -R K_e (R^T x - X).
#pragma once

#include <array>

#include "plugin/tet_rest_data.h"

namespace taut {

// Lame parameters of an element [Pa].
struct LameParameters {
  double mu = 0.0;
  double lambda = 0.0;
};

// Elastic energy Psi of the element at deformation gradient G with rotation R [J].
double CalcCorotatedTetEnergy(const TetRestElement& rest, const LameParameters& lame, const Mat3& G,
                              const Mat3& R);

// An upper bound on Psi without R (docs/math.md §4.6): for det G > 0,
//   Psi <= V (mu + 3/2 max(lambda, 0)) ||G^T G - I||_F^2;  +inf for det G <= 0.
double CalcCorotatedTetEnergyBound(const TetRestElement& rest, const LameParameters& lame,
                                   const Mat3& G);

// First Piola-Kirchhoff stress P = 2 mu (G - R) + lambda tr(R^T G - I) R [Pa].
Mat3 CalcCorotatedStress(const LameParameters& lame, const Mat3& G, const Mat3& R);

// Elastic nodal forces f_n = -V P r_n [N].
std::array<Vec3, 4> CalcCorotatedTetForces(const TetRestElement& rest, const LameParameters& lame,
                                           const Mat3& G, const Mat3& R);

// Rest stiffness block K0_nm = V [lambda r_n r_m^T + mu r_m r_n^T + mu (r_n . r_m) I] [N/m];
// the linear-elastic K_e of the element, 3x3 block coupling node n (rows) to node m (columns).
Mat3 CalcRestStiffnessBlock(const TetRestElement& rest, const LameParameters& lame, int n, int m);

// Stiffness with R frozen, K = -df/dx|_R = R K0 R^T (symmetric positive semidefinite), 12x12 in
// node-major order. This is what the implicit step uses.
Mat12 CalcFrozenRotationTetStiffness(const TetRestElement& rest, const LameParameters& lame,
                                     const Mat3& R);

// Exact stiffness K = -df/dx including dR/dx: dR = R hat(w) with
// w = (tr(S) I - S)^-1 vee(R^T dG - dG^T R); the eigenvalues s_a + s_b of (tr S I - S) are clamped
// away from zero by `clamp` (inverted elements with s_a = -s_b). Not necessarily definite.
Mat12 CalcExactTetStiffness(const TetRestElement& rest, const LameParameters& lame,
                            const std::array<Vec3, 4>& x, double clamp = 1e-6);

}  // namespace taut
