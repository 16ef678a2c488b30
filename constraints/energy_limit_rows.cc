#include "constraints/energy_limit_rows.h"

#include "plugin/polar_rotation.h"

namespace taut {

void CalcEnergyLimitJacobian(const Vec3* forces, int num_nodes, double u_max, Vec3* J) {
  // dC/dx = -(1/U_max) dU/dx = f / U_max (docs/math.md §4.5).
  const double scale = 1.0 / u_max;
  for (int n = 0; n < num_nodes; ++n) J[n] = scale * forces[n];
}

double CalcTetElementEnergy(const TetRestElement& rest, const LameParameters& lame,
                            const std::array<Vec3, 4>& x) {
  const Mat3 G = CalcTetDeformationGradient(rest, x);
  return CalcCorotatedTetEnergy(rest, lame, G, CalcPolarRotation(G));
}

TetEnergyLimitRow CalcTetEnergyLimitRow(const TetRestElement& rest, const LameParameters& lame,
                                        const std::array<Vec3, 4>& x, double u_max) {
  const Mat3 G = CalcTetDeformationGradient(rest, x);
  const Mat3 R = CalcPolarRotation(G);
  TetEnergyLimitRow row;
  row.energy = CalcCorotatedTetEnergy(rest, lame, G, R);
  row.C = CalcEnergyLimitValue(row.energy, u_max);
  const std::array<Vec3, 4> f = CalcCorotatedTetForces(rest, lame, G, R);
  std::array<Vec3, 4> J;
  CalcEnergyLimitJacobian(f.data(), 4, u_max, J.data());
  for (int n = 0; n < 4; ++n) row.J.segment<3>(3 * n) = J[n];
  return row;
}

Mat12 CalcTetEnergyLimitCurvature(const TetRestElement& rest, const LameParameters& lame,
                                  const std::array<Vec3, 4>& x, double u_max) {
  // C = 1 - U/U_max, U = 1/2 (R^T x - X)^T K0 (R^T x - X) for frozen R: -d^2C = R K0 R^T/U_max.
  const Mat3 R = CalcPolarRotation(CalcTetDeformationGradient(rest, x));
  return CalcFrozenRotationTetStiffness(rest, lame, R) / u_max;
}

double CalcHexElementEnergy(const HexRestElement& rest, const HexNodes& x,
                            HexRotationMethod method) {
  return CalcCorotatedHexEnergy(rest, x, CalcHexRotation(rest, x, method));
}

HexEnergyLimitRow CalcHexEnergyLimitRow(const HexRestElement& rest, const HexNodes& x,
                                        const Mat3& R, double u_max) {
  HexEnergyLimitRow row;
  // J = f_e / U_max with f_e = -R K_e (R^T x - X) (docs/math.md §4.5, frozen R).
  Vec24 f;
  row.energy = CalcCorotatedHexForcesAndEnergy(rest, x, R, f);
  row.C = CalcEnergyLimitValue(row.energy, u_max);
  std::array<Vec3, 8> forces, J;
  for (int n = 0; n < 8; ++n) forces[n] = f.segment<3>(3 * n);
  CalcEnergyLimitJacobian(forces.data(), 8, u_max, J.data());
  for (int n = 0; n < 8; ++n) row.J.segment<3>(3 * n) = J[n];
  return row;
}

Mat24 CalcHexEnergyLimitCurvature(const HexRestElement& rest, const Mat3& R, double u_max) {
  // -d^2C/dx^2 = -d(J)/dx = -d(f_e)/dx / U_max = R K_e R^T / U_max (frozen R).
  return CalcFrozenRotationHexStiffness(rest, R) / u_max;
}

}  // namespace taut
