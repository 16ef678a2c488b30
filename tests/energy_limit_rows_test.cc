#include "constraints/energy_limit_rows.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include "plugin/material.h"
#include "plugin/polar_rotation.h"
#include "tests/test_utils.h"

namespace taut {
namespace {

using testing::CentralDifference;
using testing::RandomRotation;
using testing::RelativeError;

// Rest data of one tet with the given rest nodes (positive orientation).
TetRestElement MakeRest(const std::array<Vec3, 4>& X) {
  TetMesh mesh;
  mesh.nodes.assign(X.begin(), X.end());
  mesh.tets = {{0, 1, 2, 3}};
  return CalcTetRestData(mesh).elements[0];
}

// A positively oriented random rest tet near the unit corner tet, scaled to ~0.1 m.
std::array<Vec3, 4> RandomRestTet(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-0.15, 0.15);
  std::array<Vec3, 4> X = {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1), Vec3(0, 0, 0)};
  for (Vec3& p : X) p = 0.1 * (p + Vec3(u(rng), u(rng), u(rng)));
  return X;
}

LameParameters TestLame() {
  const Material material{2e3, 0.3, 1000.0};
  return {material.mu(), material.lambda()};
}

VecX Flatten(const std::array<Vec3, 4>& x) {
  VecX v(12);
  for (int n = 0; n < 4; ++n) v.segment<3>(3 * n) = x[n];
  return v;
}

std::array<Vec3, 4> Unflatten(const VecX& v) {
  return {v.segment<3>(0), v.segment<3>(3), v.segment<3>(6), v.segment<3>(9)};
}

// Maps the rest tet by x = Q (A X) + t with A = I + amplitude * noise, optionally mirrored
// (inverted: det G < 0).
std::array<Vec3, 4> Deform(const std::array<Vec3, 4>& X, double amplitude, bool invert,
                           std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Mat3 A = Mat3::Identity();
  for (int i = 0; i < 9; ++i) A.data()[i] += amplitude * n(rng);
  if (invert) A.row(2) *= -1.0;
  const Mat3 Q = RandomRotation(rng);
  const Vec3 t(n(rng), n(rng), n(rng));
  std::array<Vec3, 4> x;
  for (int k = 0; k < 4; ++k) x[k] = Q * (A * X[k]) + 0.1 * t;
  return x;
}

TEST(EnergyLimitRowsTest, JacobianMatchesCentralDifferences) {
  std::mt19937 rng(7);
  const LameParameters lame = TestLame();
  double worst = 0.0;
  int inverted = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const auto X = RandomRestTet(rng);
    const TetRestElement rest = MakeRest(X);
    const bool invert = trial % 3 == 0;
    const double amplitude = trial % 2 == 0 ? 0.05 : 0.3;
    const auto x = Deform(X, amplitude, invert, rng);
    if (CalcTetDeformationGradient(rest, x).determinant() < 0.0) ++inverted;
    const double u_max = 1e-4;
    const TetEnergyLimitRow row = CalcTetEnergyLimitRow(rest, lame, x, u_max);
    const MatX fd = CentralDifference(
        [&](const VecX& v) {
          return VecX::Constant(1, CalcTetEnergyLimitRow(rest, lame, Unflatten(v), u_max).C);
        },
        Flatten(x), 1e-7);
    ASSERT_GT(fd.norm(), 1e-3) << "trial " << trial;
    ASSERT_GT(row.J.norm(), 1e-3) << "trial " << trial;
    const double error = RelativeError(row.J.transpose(), fd);
    worst = std::max(worst, error);
    EXPECT_LT(error, 1e-5) << "trial " << trial << " invert " << invert;
  }
  EXPECT_GT(inverted, 50);
  std::printf(
      "energy-limit Jacobian vs FD: worst relative error %.2e over 300 tets (%d inverted)\n", worst,
      inverted);
}

TEST(EnergyLimitRowsTest, RestAndRigidMotionGiveOneAndZeroJacobian) {
  std::mt19937 rng(3);
  const auto X = RandomRestTet(rng);
  const TetRestElement rest = MakeRest(X);
  const TetEnergyLimitRow at_rest = CalcTetEnergyLimitRow(rest, TestLame(), X, 1e-5);
  EXPECT_EQ(at_rest.C, 1.0);
  EXPECT_LT(at_rest.J.norm(), 1e-6);
  const Mat3 Q = RandomRotation(rng);
  std::array<Vec3, 4> x;
  for (int n = 0; n < 4; ++n) x[n] = Q * X[n] + Vec3(0.3, -0.2, 1.0);
  const TetEnergyLimitRow rigid = CalcTetEnergyLimitRow(rest, TestLame(), x, 1e-5);
  EXPECT_NEAR(rigid.C, 1.0, 1e-9);
  EXPECT_LT(rigid.J.norm(), 1e-3);  // vs ~1e3 /m for a strained tet at this U_max
}

TEST(EnergyLimitRowsTest, ZeroExactlyAtTheLimitAndQuadraticInStretch) {
  std::mt19937 rng(11);
  const auto X = RandomRestTet(rng);
  const TetRestElement rest = MakeRest(X);
  const LameParameters lame = TestLame();
  // Uniaxial stretch G = diag(1 + e, 1, 1): U = V (mu + lambda/2) e^2.
  auto stretched = [&](double e) {
    std::array<Vec3, 4> x = X;
    for (Vec3& p : x) p.x() *= 1.0 + e;
    return x;
  };
  const double e = 0.04;
  const double U = rest.volume * (lame.mu + 0.5 * lame.lambda) * e * e;
  EXPECT_NEAR(CalcTetElementEnergy(rest, lame, stretched(e)), U, 1e-12 * U + 1e-18);
  const double u_at = CalcTetElementEnergy(rest, lame, stretched(e));
  EXPECT_EQ(CalcTetEnergyLimitRow(rest, lame, stretched(e), u_at).C, 0.0);
  // Half the strain: a quarter of the energy, C = 3/4; twice: C = -3.
  EXPECT_NEAR(CalcTetEnergyLimitRow(rest, lame, stretched(e / 2), u_at).C, 0.75, 1e-9);
  EXPECT_NEAR(CalcTetEnergyLimitRow(rest, lame, stretched(2 * e), u_at).C, -3.0, 1e-9);
  // J = f / U_max: along the stretch the row decreases (J . dx < 0 for more stretch).
  const TetEnergyLimitRow row = CalcTetEnergyLimitRow(rest, lame, stretched(e), u_at);
  VecX dx(12);
  for (int n = 0; n < 4; ++n) dx.segment<3>(3 * n) = Vec3(X[n].x(), 0, 0);
  // dx moves node n by X_n.x along x, i.e. de = 1; dC/de = -(dU/de)/U_max = -2 U/(e U_max) = -2/e.
  EXPECT_NEAR(row.J.dot(dx), -2.0 / e, 1e-9);
}

TEST(EnergyLimitRowsTest, GenericJacobianIsForceOverLimit) {
  const std::array<Vec3, 2> f = {Vec3(1, -2, 3), Vec3(-4, 5, 0.5)};
  std::array<Vec3, 2> J;
  CalcEnergyLimitJacobian(f.data(), 2, 0.25, J.data());
  EXPECT_EQ(J[0], Vec3(4, -8, 12));
  EXPECT_EQ(J[1], Vec3(-16, 20, 2));
  EXPECT_EQ(CalcEnergyLimitValue(0.1, 0.4), 0.75);
  EXPECT_EQ(CalcEnergyLimitValue(5.0, std::numeric_limits<double>::infinity()), 1.0);
}

// A random, non-parallelepiped rest hex of edge ~0.2 m (corners of a box moved by up to 15 %).
HexNodes RandomRestHex(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-0.03, 0.03);
  HexNodes X;
  for (int a = 0; a < 8; ++a) X[a] = 0.1 * HexCornerSign(a) + Vec3(u(rng), u(rng), u(rng));
  return X;
}

VecX FlattenHex(const HexNodes& x) {
  VecX v(24);
  for (int n = 0; n < 8; ++n) v.segment<3>(3 * n) = x[n];
  return v;
}

HexNodes UnflattenHex(const VecX& v) {
  HexNodes x;
  for (int n = 0; n < 8; ++n) x[n] = v.segment<3>(3 * n);
  return x;
}

// x = Q (A X) + t with A = I + amplitude * noise, plus nodal noise of `amplitude` / 4 [m].
HexNodes DeformHex(const HexNodes& X, double amplitude, std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Mat3 A = Mat3::Identity();
  for (int i = 0; i < 9; ++i) A.data()[i] += amplitude * n(rng);
  const Mat3 Q = RandomRotation(rng);
  const Vec3 t(n(rng), n(rng), n(rng));
  HexNodes x;
  for (int a = 0; a < 8; ++a)
    x[a] = Q * (A * X[a] + 0.025 * amplitude * Vec3(n(rng), n(rng), n(rng))) + 0.1 * t;
  return x;
}

TEST(EnergyLimitRowsTest, HexJacobianMatchesCentralDifferencesWithFrozenRotation) {
  std::mt19937 rng(5);
  const LameParameters lame = TestLame();
  double worst = 0.0;
  for (int trial = 0; trial < 100; ++trial) {
    const HexRestElement rest = CalcHexRestElement(RandomRestHex(rng), lame);
    const HexNodes x = DeformHex(rest.X, trial % 2 == 0 ? 0.05 : 0.3, rng);
    const auto method =
        trial % 3 == 0 ? HexRotationMethod::kInscribedTet : HexRotationMethod::kCenterPolar;
    const Mat3 R = CalcHexRotation(rest, x, method);
    const double u_max = 1e-3;
    const HexEnergyLimitRow row = CalcHexEnergyLimitRow(rest, x, R, u_max);
    EXPECT_NEAR(row.energy, CalcHexElementEnergy(rest, x, method), 1e-15);
    EXPECT_DOUBLE_EQ(row.C, 1.0 - row.energy / u_max);
    // C(x) = 1 - U(x, R)/U_max with R held fixed.
    const MatX fd = CentralDifference(
        [&](const VecX& v) {
          return VecX::Constant(1, CalcHexEnergyLimitRow(rest, UnflattenHex(v), R, u_max).C);
        },
        FlattenHex(x), 1e-7);
    ASSERT_GT(fd.norm(), 1e-1) << "trial " << trial;
    ASSERT_GT(row.J.norm(), 1e-1) << "trial " << trial;
    const double error = RelativeError(row.J.transpose(), fd);
    worst = std::max(worst, error);
    EXPECT_LT(error, 1e-6) << "trial " << trial;
  }
  std::printf("hex energy-limit Jacobian (R frozen) vs FD: worst relative error %.2e\n", worst);
}

TEST(EnergyLimitRowsTest, HexJacobianApproximatesFullGradientAtSmallStrain) {
  // docs/math.md §4.5: neglecting dR/dx costs about 2a relative error at nodal strain noise a.
  std::mt19937 rng(9);
  const LameParameters lame = TestLame();
  for (int trial = 0; trial < 20; ++trial) {
    const HexRestElement rest = CalcHexRestElement(RandomRestHex(rng), lame);
    const HexNodes x = DeformHex(rest.X, 1e-3, rng);
    const double u_max = 1e-6;
    const HexEnergyLimitRow row = CalcHexEnergyLimitRow(
        rest, x, CalcHexRotation(rest, x, HexRotationMethod::kCenterPolar), u_max);
    // C(x) with R = R(x) recomputed at every evaluation.
    const MatX fd = CentralDifference(
        [&](const VecX& v) {
          return VecX::Constant(1, 1.0 - CalcHexElementEnergy(rest, UnflattenHex(v),
                                                              HexRotationMethod::kCenterPolar) /
                                             u_max);
        },
        FlattenHex(x), 1e-8);
    ASSERT_GT(fd.norm(), 1e-3);
    EXPECT_LT(RelativeError(row.J.transpose(), fd), 2e-2) << "trial " << trial;
  }
}

TEST(EnergyLimitRowsTest, HexRestAndRigidMotionGiveOneAndZeroJacobian) {
  std::mt19937 rng(4);
  const HexRestElement rest = CalcHexRestElement(RandomRestHex(rng), TestLame());
  const HexEnergyLimitRow at_rest = CalcHexEnergyLimitRow(rest, rest.X, Mat3::Identity(), 1e-5);
  EXPECT_EQ(at_rest.C, 1.0);
  EXPECT_LT(at_rest.J.norm(), 1e-6);
  const Mat3 Q = RandomRotation(rng);
  HexNodes x;
  for (int n = 0; n < 8; ++n) x[n] = Q * rest.X[n] + Vec3(0.3, -0.2, 1.0);
  for (auto method : {HexRotationMethod::kCenterPolar, HexRotationMethod::kInscribedTet}) {
    const HexEnergyLimitRow rigid =
        CalcHexEnergyLimitRow(rest, x, CalcHexRotation(rest, x, method), 1e-5);
    EXPECT_NEAR(rigid.C, 1.0, 1e-9);
    EXPECT_LT(rigid.J.norm(), 1e-3);
  }
}

TEST(EnergyLimitRowsTest, HexUniaxialStretchEnergyAndLimitValue) {
  // Box hex 0.2 m, G = diag(1 + e, 1, 1): U = V (mu + lambda/2) e^2 (uniform strain, exact).
  const LameParameters lame = TestLame();
  HexNodes X;
  for (int a = 0; a < 8; ++a) X[a] = 0.1 * HexCornerSign(a);
  const HexRestElement rest = CalcHexRestElement(X, lame);
  const double e = 0.02;
  HexNodes x = X;
  for (Vec3& p : x) p.x() *= 1.0 + e;
  const double U = 0.008 * (lame.mu + 0.5 * lame.lambda) * e * e;
  const double u = CalcHexElementEnergy(rest, x, HexRotationMethod::kCenterPolar);
  EXPECT_NEAR(u, U, 1e-12 * U);
  const HexEnergyLimitRow row = CalcHexEnergyLimitRow(rest, x, Mat3::Identity(), 2.0 * U);
  EXPECT_NEAR(row.C, 0.5, 1e-12);
  // dC/de = -(dU/de)/U_max = -2 U/(e U_max) = -1/e along dx_n = (X_n.x, 0, 0).
  VecX dx = VecX::Zero(24);
  for (int n = 0; n < 8; ++n) dx[3 * n] = X[n].x();
  EXPECT_NEAR(row.J.dot(dx), -1.0 / e, 1e-9 / e);
}

// Smallest eigenvalue over the norm of a symmetric matrix.
template <typename M>
double MinEigenvalueRatio(const M& H) {
  return Eigen::SelfAdjointEigenSolver<M>(H, Eigen::EigenvaluesOnly).eigenvalues()[0] / H.norm();
}

// Curvature -d^2C/dx^2 = R K0 R^T/U_max: the row's J is the warped force over U_max,
// J = -R K0 (R^T x - X)/U_max at R = polar(G) (corotated_tet_element.h), and the curvature is
// the central difference of that J with R frozen.
TEST(EnergyLimitRowsTest, TetCurvatureMatchesFdOfFrozenRotationJacobian) {
  std::mt19937 rng(11);
  const LameParameters lame = TestLame();
  double worst = 0.0, worst_value = 0.0;
  for (int trial = 0; trial < 100; ++trial) {
    const auto X = RandomRestTet(rng);
    const TetRestElement rest = MakeRest(X);
    const auto x = Deform(X, trial % 2 == 0 ? 0.05 : 0.3, trial % 3 == 0, rng);
    const double u_max = 1e-4;
    const Mat3 R = CalcPolarRotation(CalcTetDeformationGradient(rest, x));
    const Mat12 K0 = CalcFrozenRotationTetStiffness(rest, lame, Mat3::Identity());
    Eigen::Matrix<double, 12, 12> R_bd = Eigen::Matrix<double, 12, 12>::Zero();
    for (int n = 0; n < 4; ++n) R_bd.block<3, 3>(3 * n, 3 * n) = R;
    const auto frozen_jacobian = [&](const VecX& v) -> VecX {
      return -R_bd * K0 * (R_bd.transpose() * v - Flatten(X)) / u_max;
    };
    // The frozen-rotation J is the row's J at x ...
    const VecX J_row = CalcTetEnergyLimitRow(rest, lame, x, u_max).J;
    worst_value = std::max(worst_value, RelativeError(frozen_jacobian(Flatten(x)), J_row));
    // ... and the curvature is its derivative.
    const Mat12 H = CalcTetEnergyLimitCurvature(rest, lame, x, u_max);
    const MatX fd = CentralDifference(frozen_jacobian, Flatten(x), 1e-7);
    ASSERT_GT(fd.norm(), 1.0);
    const double error = RelativeError(H, -fd);
    worst = std::max(worst, error);
    EXPECT_LT(error, 1e-6) << "trial " << trial;
    EXPECT_GE(MinEigenvalueRatio(H), -1e-12);
  }
  std::printf(
      "tet energy-limit curvature vs FD of J (R frozen): worst relative error %.2e (J at x vs "
      "row J: %.2e)\n",
      worst, worst_value);
  EXPECT_LT(worst_value, 1e-9);
}

// Hex: -d^2C/dx^2 = R K_e R^T/U_max against central differences of CalcHexEnergyLimitRow's J.
TEST(EnergyLimitRowsTest, HexCurvatureMatchesFdOfFrozenRotationJacobian) {
  std::mt19937 rng(12);
  const LameParameters lame = TestLame();
  double worst = 0.0;
  for (int trial = 0; trial < 40; ++trial) {
    const HexRestElement rest = CalcHexRestElement(RandomRestHex(rng), lame);
    const HexNodes x = DeformHex(rest.X, trial % 2 == 0 ? 0.05 : 0.3, rng);
    const Mat3 R = CalcHexRotation(rest, x, HexRotationMethod::kCenterPolar);
    const double u_max = 1e-3;
    const Mat24 H = CalcHexEnergyLimitCurvature(rest, R, u_max);
    const MatX fd = CentralDifference(
        [&](const VecX& v) {
          return VecX(CalcHexEnergyLimitRow(rest, UnflattenHex(v), R, u_max).J);
        },
        FlattenHex(x), 1e-7);
    ASSERT_GT(fd.norm(), 1.0);
    const double error = RelativeError(H, -fd);
    worst = std::max(worst, error);
    EXPECT_LT(error, 1e-6) << "trial " << trial;
    EXPECT_GE(MinEigenvalueRatio(H), -1e-12);
  }
  std::printf("hex energy-limit curvature vs FD of J (R frozen): worst relative error %.2e\n",
              worst);
}

}  // namespace
}  // namespace taut
