// Energy-limit constraint rows (paper B eq. 14; docs/math.md §4.5): per element
//   C = 1 - U_e / U_max >= 0,   dC/dx = -(1/U_max) dU_e/dx = f_e / U_max,
// where f_e is the element's elastic force. C = 1 at rest, 0 at the limit, < 0 beyond it.
// For hexes with R frozen, f_e = -R K_e (R^T x - X) (docs/math.md §4.5 / §6 B4), so any element
// type only needs its energy and forces. For co-rotated tets with R = polar(G) the force is the
// exact gradient of U (plugin/corotated_tet_element.h), so the tet Jacobian is exact.
#pragma once

#include "plugin/corotated_hex_element.h"
#include "plugin/corotated_tet_element.h"

namespace taut {

// C = 1 - U/U_max [-]; U_max = +inf gives 1 (unlimited element).
inline double CalcEnergyLimitValue(double energy, double u_max) { return 1.0 - energy / u_max; }

// dC/dx_n = f_n / U_max for n < num_nodes [1/m]; f are the element's elastic forces [N].
void CalcEnergyLimitJacobian(const Vec3* forces, int num_nodes, double u_max, Vec3* J);

// Energy limit of one tet, linearised: C(x + dx) ~ C + J . dx.
struct TetEnergyLimitRow {
  Vec12 J = Vec12::Zero();  // dC/dx, ordered (x_1, x_2, x_3, x_4) each xyz [1/m]
  double C = 1.0;           // 1 - U/U_max [-]
  double energy = 0.0;      // U_e [J]
};

// Co-rotated energy U_e of a tet at node positions x, with R = polar(G) [J].
double CalcTetElementEnergy(const TetRestElement& rest, const LameParameters& lame,
                            const std::array<Vec3, 4>& x);

// C, U_e and the exact Jacobian -grad U / U_max of a tet at node positions x (U_max > 0).
TetEnergyLimitRow CalcTetEnergyLimitRow(const TetRestElement& rest, const LameParameters& lame,
                                        const std::array<Vec3, 4>& x, double u_max);

// Curvature -d^2 C/dx^2 = K_e(R)/U_max = R K0 R^T / U_max of a tet's energy row with the rotation
// R = polar(G(x)) frozen (12x12, node-major, PSD; U_max > 0): the lagged geometric stiffness of
// the row (issue 11 item 3; docs/math.md §5.9, a per-element stiffness factor).
Mat12 CalcTetEnergyLimitCurvature(const TetRestElement& rest, const LameParameters& lame,
                                  const std::array<Vec3, 4>& x, double u_max);

// Energy limit of one hex, linearised with the element rotation R frozen: C(x + dx) ~ C + J . dx.
struct HexEnergyLimitRow {
  Vec24 J = Vec24::Zero();  // dC/dx = f_e / U_max, node-major (local hex order) xyz [1/m]
  double C = 1.0;           // 1 - U/U_max [-]
  double energy = 0.0;      // U_e [J]
};

// Co-rotated energy U_e = 1/2 (R^T x - X)^T K_e (R^T x - X) of a hex, R from x by `method` [J].
double CalcHexElementEnergy(const HexRestElement& rest, const HexNodes& x,
                            HexRotationMethod method);

// C, U_e and J = f_e/U_max = -R K_e (R^T x - X)/U_max of a hex with R frozen (docs/math.md §4.5),
// the exact gradient of C(x) = 1 - U(x, R)/U_max for fixed R (U_max > 0).
HexEnergyLimitRow CalcHexEnergyLimitRow(const HexRestElement& rest, const HexNodes& x,
                                        const Mat3& R, double u_max);

// Curvature -d^2 C/dx^2 = R K_e R^T / U_max of a hex's energy row with R frozen (24x24, PSD;
// U_max > 0), the derivative of CalcHexEnergyLimitRow's J (docs/math.md §4.5).
Mat24 CalcHexEnergyLimitCurvature(const HexRestElement& rest, const Mat3& R, double u_max);

}  // namespace taut
