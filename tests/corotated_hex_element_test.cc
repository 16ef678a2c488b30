#include "plugin/corotated_hex_element.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "plugin/material.h"
#include "plugin/polar_rotation.h"
#include "tests/test_utils.h"

namespace taut {
namespace {

using testing::CentralDifference;
using testing::RelativeError;

const Material kMaterial{1e5, 0.3, 1000};
const LameParameters kLame{kMaterial.mu(), kMaterial.lambda()};
constexpr double kPi = 3.14159265358979323846;

// Rest hex: cube of edge `edge` at `corner`, mapped by the affine B and with node noise.
HexNodes MakeRestHex(std::mt19937& rng, double edge, const Mat3& B, double noise) {
  std::uniform_real_distribution<double> u(-noise, noise);
  HexNodes X;
  for (int a = 0; a < 8; ++a)
    X[a] =
        Vec3(0.3, -0.2, 0.1) + B * (0.5 * edge * HexCornerSign(a)) + Vec3(u(rng), u(rng), u(rng));
  return X;
}

// A distorted (non-parallelepiped) rest hex, edge about 0.5.
HexNodes MakeDistortedHex(std::mt19937& rng) {
  Mat3 B;
  B << 1.0, 0.2, -0.1, 0.05, 0.8, 0.15, -0.1, 0.1, 1.2;
  return MakeRestHex(rng, 0.5, B, 0.04);
}

VecX Flatten(const HexNodes& x) {
  VecX q(24);
  for (int a = 0; a < 8; ++a) q.segment<3>(3 * a) = x[a];
  return q;
}

HexNodes Unflatten(const VecX& q) {
  HexNodes x;
  for (int a = 0; a < 8; ++a) x[a] = q.segment<3>(3 * a);
  return x;
}

// Random deformed state: rotation times stretch (about 5 % strain) plus nodal noise.
HexNodes RandomState(std::mt19937& rng, const HexNodes& X, double strain, bool invert = false) {
  std::uniform_real_distribution<double> u(-strain, strain);
  const Mat3 Q = testing::RandomRotation(rng);
  Mat3 S = Mat3::Identity();
  for (int k = 0; k < 9; ++k) S.data()[k] += u(rng);
  if (invert) S.col(2) *= -0.5;
  HexNodes x;
  for (int a = 0; a < 8; ++a)
    x[a] = Q * S * X[a] + 0.3 * Vec3(u(rng), u(rng), u(rng)) + Vec3(1, 2, 3);
  return x;
}

// Rotation angle of a rotation matrix [deg].
double AngleDeg(const Mat3& R) {
  return std::acos(std::clamp((R.trace() - 1.0) / 2.0, -1.0, 1.0)) * 180.0 / kPi;
}

TEST(CorotatedHexElementTest, ForcesAreMinusEnergyGradientWithFrozenRotation) {
  std::mt19937 rng(1);
  for (const auto method : {HexRotationMethod::kCenterPolar, HexRotationMethod::kInscribedTet}) {
    for (int trial = 0; trial < 5; ++trial) {
      const HexRestElement rest = CalcHexRestElement(MakeDistortedHex(rng), kLame);
      const HexNodes x = RandomState(rng, rest.X, 0.05);
      const Mat3 R = CalcHexRotation(rest, x, method);
      const VecX f = CalcCorotatedHexForces(rest, x, R);
      const MatX grad = CentralDifference(
          [&](const VecX& q) {
            return VecX::Constant(1, CalcCorotatedHexEnergy(rest, Unflatten(q), R));
          },
          Flatten(x), 1e-6);
      ASSERT_GT(f.norm(), 1e2);
      EXPECT_LT(RelativeError(-grad.transpose(), f), 1e-7) << "trial " << trial;
    }
  }
}

TEST(CorotatedHexElementTest, FrozenStiffnessIsMinusForceJacobian) {
  std::mt19937 rng(2);
  for (int trial = 0; trial < 5; ++trial) {
    const HexRestElement rest = CalcHexRestElement(MakeDistortedHex(rng), kLame);
    const HexNodes x = RandomState(rng, rest.X, 0.05, trial == 4);
    const Mat3 R = CalcHexRotation(rest, x, HexRotationMethod::kCenterPolar);
    const MatX J = CentralDifference(
        [&](const VecX& q) -> VecX { return CalcCorotatedHexForces(rest, Unflatten(q), R); },
        Flatten(x), 1e-6);
    const Mat24 K = CalcFrozenRotationHexStiffness(rest, R);
    ASSERT_GT(J.norm(), 1e3);
    EXPECT_LT(RelativeError(K, -J), 1e-8) << "trial " << trial;
  }
}

TEST(CorotatedHexElementTest, RotatedBlocksFromTheUpperHalfMatchTheFullProduct) {
  // The 28 lower blocks are taken as transposes of the upper ones (K_e exactly symmetric).
  std::mt19937 rng(7);
  for (int trial = 0; trial < 4; ++trial) {
    const HexRestElement rest = CalcHexRestElement(MakeDistortedHex(rng), kLame);
    EXPECT_EQ(rest.stiffness(), rest.stiffness().transpose());
    const Mat3 R = testing::RandomRotation(rng);
    const double scale = 0.37;
    HexStiffnessBlocks blocks;
    CalcRotatedHexStiffnessBlocks(rest, R, scale, blocks);
    for (int a = 0; a < 8; ++a)
      for (int b = 0; b < 8; ++b) {
        const Mat3 expected =
            scale * R * rest.stiffness().block<3, 3>(3 * a, 3 * b) * R.transpose();
        EXPECT_LT((blocks[8 * a + b] - expected).norm(), 1e-12 * rest.stiffness().norm())
            << "trial " << trial << " block " << a << ", " << b;
      }
  }
}

TEST(CorotatedHexElementTest, ForcesAndEnergyFromOneProductMatchTheSeparateCalls) {
  std::mt19937 rng(8);
  const HexRestElement rest = CalcHexRestElement(MakeDistortedHex(rng), kLame);
  const HexNodes x = RandomState(rng, rest.X, 0.05);
  const Mat3 R = CalcHexRotation(rest, x, HexRotationMethod::kCenterPolar);
  Vec24 f;
  const double U = CalcCorotatedHexForcesAndEnergy(rest, x, R, f);
  ASSERT_GT(U, 0.0);
  EXPECT_EQ(U, CalcCorotatedHexEnergy(rest, x, R));
  EXPECT_EQ(f, CalcCorotatedHexForces(rest, x, R));
}

TEST(CorotatedHexElementTest, EqualCellsShareOneStiffnessAndDistortedOnesKeepTheirOwn) {
  // A lattice 1 km from the origin: its cells' X_a - X_0 differ in the last bits (ulp(1234.5) /
  // 0.1 = 2e-12), their K_e by as much, so they share one; a cell with a moved node keeps its own.
  HexLattice lattice = MakeBoxHexLattice(Vec3(0.3, 0.2, 0.1), 3, 2, 1, Vec3(1234.5, -77.25, 3.1));
  lattice.nodes[0] += Vec3(0.01, 0.0, 0.0);  // a corner of cell 0 only
  std::vector<HexRestElement> own, shared;
  for (const auto& hex : lattice.hexes) {
    HexNodes X;
    for (int a = 0; a < 8; ++a) X[a] = lattice.nodes[hex[a]];
    own.push_back(CalcHexRestElement(X, kLame));
  }
  shared = own;
  for (auto& rest : shared)  // copies share the matrix; give each its own again
    rest.shared_stiffness = std::make_shared<const Mat24>(rest.stiffness());
  ShareEqualHexStiffnesses(shared);
  EXPECT_EQ(shared[0].shared_stiffness.use_count(), 1) << "the distorted cell";
  for (int e = 2; e < static_cast<int>(shared.size()); ++e)
    EXPECT_EQ(shared[e].shared_stiffness, shared[1].shared_stiffness) << "cell " << e;
  std::mt19937 rng(9);
  for (int e = 0; e < static_cast<int>(shared.size()); ++e) {
    const double scale = own[e].stiffness().cwiseAbs().maxCoeff();
    EXPECT_LE((shared[e].stiffness() - own[e].stiffness()).cwiseAbs().maxCoeff(),
              kSharedHexStiffnessTolerance * scale)
        << "cell " << e;
    const HexNodes x = RandomState(rng, own[e].X, 0.05);
    const Mat3 R = CalcHexRotation(own[e], x, HexRotationMethod::kCenterPolar);
    const Vec24 f_own = CalcCorotatedHexForces(own[e], x, R);
    EXPECT_LE((CalcCorotatedHexForces(shared[e], x, R) - f_own).norm(), 1e-8 * f_own.norm())
        << "cell " << e;
  }
}

TEST(CorotatedHexElementTest, EnergyBoundWithoutRotationHoldsForBothRotationMethods) {
  std::mt19937 rng(22);
  for (int trial = 0; trial < 200; ++trial) {
    const HexRestElement rest = CalcHexRestElement(MakeDistortedHex(rng), kLame);
    const double strain = trial % 3 == 0 ? 0.3 : (trial % 3 == 1 ? 0.05 : 1e-3);
    const HexNodes x = RandomState(rng, rest.X, strain, /*invert=*/trial % 20 == 19);
    for (const Mat3& G : {CalcHexCenterDeformationGradient(rest, x),
                          CalcHexInscribedTetDeformationGradient(rest, x, 0)}) {
      const double bound = CalcCorotatedHexEnergyBound(rest, x, G);
      if (!(G.determinant() > 0.0)) {
        EXPECT_EQ(bound, HUGE_VAL) << "trial " << trial << ": inverted";
        continue;
      }
      EXPECT_GE(bound, CalcCorotatedHexEnergy(rest, x, CalcPolarRotation(G)))
          << "trial " << trial << ", strain " << strain;
    }
  }
  // A rotated small uniform stretch: the bound is loose by a bounded factor (the volumetric
  // eigenvalue of K_e over the stretch mode's), so elements far below a limit are skipped.
  const HexRestElement rest = CalcHexRestElement(MakeDistortedHex(rng), kLame);
  const Mat3 F = testing::RandomRotation(rng) * Vec3(1.001, 1.0, 1.0).asDiagonal();
  HexNodes x;
  for (int a = 0; a < 8; ++a) x[a] = F * rest.X[a];
  const Mat3 G = CalcHexCenterDeformationGradient(rest, x);
  EXPECT_LT(CalcCorotatedHexEnergyBound(rest, x, G),
            100.0 * CalcCorotatedHexEnergy(rest, x, CalcPolarRotation(G)));
}

TEST(CorotatedHexElementTest, RestStiffnessIsSymmetricPsdWithSixRigidModes) {
  std::mt19937 rng(3);
  const HexRestElement rest = CalcHexRestElement(MakeDistortedHex(rng), kLame);
  const Mat24& K = rest.stiffness();
  EXPECT_LT((K - K.transpose()).norm(), 1e-12 * K.norm());
  const Eigen::SelfAdjointEigenSolver<Mat24> eig(K);
  const auto& ev = eig.eigenvalues();  // ascending
  const double scale = ev[23];
  for (int i = 0; i < 6; ++i) EXPECT_LT(std::abs(ev[i]), 1e-10 * scale) << "eigenvalue " << i;
  EXPECT_GT(ev[6], 1e-3 * scale);  // exactly six zero modes: 2x2x2 rule has no hourglass modes
}

TEST(CorotatedHexElementTest, EnergyIsGaussSumOfStrainEnergyDensity) {
  // U = 1/2 u^T K_e u must equal sum_q det F_q (mu eps:eps + lambda/2 tr(eps)^2).
  std::mt19937 rng(4);
  const HexRestElement rest = CalcHexRestElement(MakeDistortedHex(rng), kLame);
  const HexNodes x = RandomState(rng, rest.X, 0.05);
  const Mat3 R = CalcHexRotation(rest, x, HexRotationMethod::kCenterPolar);
  double sum = 0.0;
  for (int q = 0; q < 8; ++q) {
    const Mat3 eps = CalcHexGaussStrain(rest, x, R, q);
    sum += rest.weights[q] *
           (kLame.mu * eps.squaredNorm() + 0.5 * kLame.lambda * std::pow(eps.trace(), 2));
  }
  ASSERT_GT(sum, 1.0);
  EXPECT_NEAR(CalcCorotatedHexEnergy(rest, x, R), sum, 1e-10 * sum);
  // The volume is the Gauss sum of det F (exact for trilinear maps): compare with a parallelepiped.
  std::mt19937 rng2(5);
  const HexRestElement cube =
      CalcHexRestElement(MakeRestHex(rng2, 0.5, 2.0 * Mat3::Identity(), 0.0), kLame);
  EXPECT_NEAR(cube.volume, 1.0, 1e-12);
}

TEST(CorotatedHexElementTest, RigidMotionGivesZeroForceAndEnergy) {
  std::mt19937 rng(6);
  const HexRestElement rest = CalcHexRestElement(MakeDistortedHex(rng), kLame);
  for (const auto method : {HexRotationMethod::kCenterPolar, HexRotationMethod::kInscribedTet}) {
    for (int trial = 0; trial < 5; ++trial) {
      // Large rotation (angle up to ~180 deg) plus translation.
      const Mat3 Q = Eigen::AngleAxisd(0.5 + 0.6 * trial, testing::RandomRotation(rng).col(0))
                         .toRotationMatrix();
      HexNodes x;
      for (int a = 0; a < 8; ++a) x[a] = Q * rest.X[a] + Vec3(5, -3, 2);
      const Mat3 R = CalcHexRotation(rest, x, method);
      EXPECT_LT((R - Q).norm(), 1e-12);
      EXPECT_LT(CalcCorotatedHexForces(rest, x, R).norm(), 1e-9);
      EXPECT_LT(CalcCorotatedHexEnergy(rest, x, R), 1e-20);  // 1e-10 without centring u
    }
  }
}

TEST(CorotatedHexElementTest, RotationIsProperForInvertedElements) {
  std::mt19937 rng(7);
  const HexRestElement rest = CalcHexRestElement(MakeDistortedHex(rng), kLame);
  for (int trial = 0; trial < 20; ++trial) {
    const HexNodes x = RandomState(rng, rest.X, 0.3, true);
    ASSERT_LT(CalcHexCenterDeformationGradient(rest, x).determinant(), 0.0);
    for (const auto method : {HexRotationMethod::kCenterPolar, HexRotationMethod::kInscribedTet}) {
      const Mat3 R = CalcHexRotation(rest, x, method);
      EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
      EXPECT_LT((R.transpose() * R - Mat3::Identity()).norm(), 1e-12);
    }
  }
}

TEST(CorotatedHexElementTest, CenterRotationIgnoresBendingButInscribedTetAliasesIt) {
  // Pure bending mode x = X + A edge s1 s2 e1 on a cube of edge 0.5 (docs/math.md §4.4 caveat). On
  // the tet {1,4,6,7}, s1 s2 = -s3, so it sees the shear G = I - 2 A e1 e3^T (X3 = edge s3 / 2)
  // whose polar rotation is atan(A): 2.862 deg at A = 0.05. G(0) = I: no rotation.
  std::mt19937 rng(8);
  const double edge = 0.5;
  const HexRestElement rest =
      CalcHexRestElement(MakeRestHex(rng, edge, Mat3::Identity(), 0.0), kLame);
  for (const double A : {0.05, 0.2}) {
    HexNodes x = rest.X;
    for (int a = 0; a < 8; ++a) {
      const Vec3 s = HexCornerSign(a);
      x[a] += A * edge * s.x() * s.y() * Vec3::UnitX();
    }
    const double center = AngleDeg(CalcHexRotation(rest, x, HexRotationMethod::kCenterPolar));
    const double tet = AngleDeg(CalcHexRotation(rest, x, HexRotationMethod::kInscribedTet));
    std::printf("bending A = %.2f: polar(G(0)) %.3g deg, tet {1,4,6,7} %.4f deg\n", A, center, tet);
    EXPECT_LT(center, 1e-6);
    EXPECT_NEAR(tet, std::atan(A) * 180.0 / kPi, 1e-6);
  }
}

TEST(CorotatedHexElementTest, CenterGradientIsMeanOfInscribedTetGradients) {
  // G(0) = 1/2 (G_1467 + G_2358) for a parallelepiped rest hex (both tets then share the rest
  // map); the deformed hex is arbitrary.
  std::mt19937 rng(9);
  for (int trial = 0; trial < 10; ++trial) {
    Mat3 B = Mat3::Identity();
    std::uniform_real_distribution<double> u(-0.3, 0.3);
    for (int k = 0; k < 9; ++k) B.data()[k] += u(rng);
    const HexRestElement rest = CalcHexRestElement(MakeRestHex(rng, 0.5, B, 0.0), kLame);
    const HexNodes x = RandomState(rng, rest.X, 0.2);
    const Mat3 G0 = CalcHexCenterDeformationGradient(rest, x);
    const Mat3 G1 = CalcHexInscribedTetDeformationGradient(rest, x, 0);
    const Mat3 G2 = CalcHexInscribedTetDeformationGradient(rest, x, 1);
    ASSERT_GT((G1 - G2).norm(), 1e-2);  // the two tets really differ
    EXPECT_LT((G0 - 0.5 * (G1 + G2)).norm(), 1e-13 * G0.norm()) << "trial " << trial;
  }
}

TEST(CorotatedHexElementTest, InvertedRestHexIsRejected) {
  std::mt19937 rng(10);
  HexNodes X = MakeDistortedHex(rng);
  std::swap(X[0], X[4]);
  std::swap(X[1], X[5]);
  std::swap(X[2], X[6]);
  std::swap(X[3], X[7]);
  EXPECT_THROW(CalcHexRestElement(X, kLame), InputError);
}

}  // namespace
}  // namespace taut
