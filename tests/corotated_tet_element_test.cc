#include "plugin/corotated_tet_element.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>

#include "plugin/box_tet_mesher.h"
#include "plugin/polar_rotation.h"
#include "plugin/tet_element_model.h"
#include "plugin/tet_element_traits.h"
#include "tests/test_utils.h"

namespace taut {
namespace {

using testing::CentralDifference;
using testing::RelativeError;

const LameParameters kLame{Material{1e5, 0.3, 1000}.mu(), Material{1e5, 0.3, 1000}.lambda()};

// A reference tet and its rest data.
TetRestElement MakeRest(std::array<Vec3, 4>& X) {
  X = {Vec3(1, 0.1, 0), Vec3(0.1, 0, 0), Vec3(0, 1.1, 0.2), Vec3(0.2, 0.1, 0.9)};
  TetMesh mesh{{X[0], X[1], X[2], X[3]}, {{0, 1, 2, 3}}, "tet"};
  if (CalcTetSignedVolume(X[0], X[1], X[2], X[3]) < 0) std::swap(mesh.tets[0][0], mesh.tets[0][1]);
  TAUT_DEMAND(mesh.tets[0][0] == 0, "test tet must be positively oriented");
  return CalcTetRestData(mesh).elements[0];
}

VecX Flatten(const std::array<Vec3, 4>& x) {
  VecX q(12);
  for (int n = 0; n < 4; ++n) q.segment<3>(3 * n) = x[n];
  return q;
}

std::array<Vec3, 4> Unflatten(const VecX& q) {
  return {q.segment<3>(0), q.segment<3>(3), q.segment<3>(6), q.segment<3>(9)};
}

// Random deformed state: rotation times stretch plus noise; `invert` flips through a plane.
std::array<Vec3, 4> RandomState(std::mt19937& rng, const std::array<Vec3, 4>& X, bool invert) {
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  const Mat3 Q = testing::RandomRotation(rng);
  Mat3 S = Mat3::Identity();
  for (int k = 0; k < 9; ++k) S.data()[k] += u(rng);
  if (invert) S.col(2) *= -0.5;
  std::array<Vec3, 4> x;
  for (int n = 0; n < 4; ++n) x[n] = Q * S * X[n] + Vec3(u(rng), u(rng), u(rng));
  return x;
}

VecX Forces(const TetRestElement& rest, const VecX& q) {
  const auto x = Unflatten(q);
  const Mat3 G = CalcTetDeformationGradient(rest, x);
  return Flatten(CalcCorotatedTetForces(rest, kLame, G, CalcPolarRotation(G)));
}

TEST(CorotatedTetElementTest, EnergyBoundWithoutRotationHoldsAndIsTightAtSmallStrain) {
  std::array<Vec3, 4> X;
  const TetRestElement rest = MakeRest(X);
  std::mt19937 rng(21);
  for (int trial = 0; trial < 200; ++trial) {
    const auto x = RandomState(rng, X, /*invert=*/trial % 10 == 9);
    const Mat3 G = CalcTetDeformationGradient(rest, x);
    const double U = CalcCorotatedTetEnergy(rest, kLame, G, CalcPolarRotation(G));
    const double bound = CalcCorotatedTetEnergyBound(rest, kLame, G);
    if (!(G.determinant() > 0.0)) {
      EXPECT_EQ(bound, HUGE_VAL) << "trial " << trial << ": inverted";
      continue;
    }
    EXPECT_GE(bound, U) << "trial " << trial;
  }
  // Rotated small uniaxial stretch e: U = V (mu + lambda/2) e^2, the bound 4 V (mu + 3/2 lambda)
  // e^2 to first order: loose by a factor below 12, so elements far from a limit are skipped.
  const Mat3 Q = testing::RandomRotation(rng);
  const Mat3 G = Q * Vec3(1.001, 1.0, 1.0).asDiagonal();
  const double U = CalcCorotatedTetEnergy(rest, kLame, G, CalcPolarRotation(G));
  EXPECT_LT(CalcCorotatedTetEnergyBound(rest, kLame, G), 12.0 * U);
}

TEST(CorotatedTetElementTest, ForcesAreMinusEnergyGradient) {
  std::array<Vec3, 4> X;
  const TetRestElement rest = MakeRest(X);
  std::mt19937 rng(3);
  for (int trial = 0; trial < 200; ++trial) {
    const VecX q = Flatten(RandomState(rng, X, trial % 4 == 0));
    auto energy = [&](const VecX& p) {
      const Mat3 G = CalcTetDeformationGradient(rest, Unflatten(p));
      return VecX::Constant(1, CalcCorotatedTetEnergy(rest, kLame, G, CalcPolarRotation(G)));
    };
    const VecX grad = CentralDifference(energy, q, 1e-6).transpose();
    const VecX f = Forces(rest, q);
    ASSERT_GT(f.norm(), 1.0);
    EXPECT_LT(RelativeError(-grad, f), 1e-6) << "trial " << trial;
  }
}

TEST(CorotatedTetElementTest, ExactStiffnessIsMinusForceDerivative) {
  std::array<Vec3, 4> X;
  const TetRestElement rest = MakeRest(X);
  std::mt19937 rng(4);
  for (int trial = 0; trial < 200; ++trial) {
    const auto x = RandomState(rng, X, trial % 4 == 0);
    const MatX dfdx =
        CentralDifference([&](const VecX& p) { return Forces(rest, p); }, Flatten(x), 1e-6);
    const Mat12 K = CalcExactTetStiffness(rest, kLame, x);
    ASSERT_GT(K.norm(), 1e3);
    EXPECT_LT(RelativeError(K, -dfdx), 1e-6) << "trial " << trial;
  }
}

TEST(CorotatedTetElementTest, FrozenStiffnessIsDerivativeWithRotationHeld) {
  std::array<Vec3, 4> X;
  const TetRestElement rest = MakeRest(X);
  std::mt19937 rng(5);
  const auto x = RandomState(rng, X, false);
  const Mat3 R = CalcPolarRotation(CalcTetDeformationGradient(rest, x));
  // Warped force -R K0 (R^T x - X) with R held; equals the co-rotated force at R = polar(G).
  std::array<Vec3, 4> X_rest = X;
  auto frozen_forces = [&](const VecX& p) {
    const auto xp = Unflatten(p);
    VecX f = VecX::Zero(12);
    for (int n = 0; n < 4; ++n)
      for (int m = 0; m < 4; ++m)
        f.segment<3>(3 * n) -=
            R * CalcRestStiffnessBlock(rest, kLame, n, m) * (R.transpose() * xp[m] - X_rest[m]);
    return f;
  };
  EXPECT_LT(RelativeError(frozen_forces(Flatten(x)), Forces(rest, Flatten(x))), 1e-10);
  const MatX dfdx = CentralDifference(frozen_forces, Flatten(x), 1e-6);
  const Mat12 K = CalcFrozenRotationTetStiffness(rest, kLame, R);
  EXPECT_LT(RelativeError(K, -dfdx), 1e-8);
  // Symmetric positive semidefinite with exactly 6 zero modes (rigid motions).
  Eigen::SelfAdjointEigenSolver<Mat12> eig(K);
  EXPECT_LT((K - K.transpose()).norm(), 1e-9 * K.norm());
  int zero = 0;
  for (int k = 0; k < 12; ++k) {
    EXPECT_GT(eig.eigenvalues()[k], -1e-9 * K.norm());
    if (std::abs(eig.eigenvalues()[k]) < 1e-9 * K.norm()) ++zero;
  }
  EXPECT_EQ(zero, 6);
}

// The assembly's closed form scale R K0_nm R^T = scale V (lambda q_n q_m^T + mu q_m q_n^T +
// mu (r_n . r_m) I), q_n = R r_n, against the rotated rest blocks, and its exact symmetry.
TEST(CorotatedTetElementTest, RotatedStiffnessBlocksAreTheRotatedRestBlocks) {
  std::array<Vec3, 4> X;
  const TetRestElement rest = MakeRest(X);
  std::mt19937 rng(11);
  for (int trial = 0; trial < 5; ++trial) {
    const auto x = RandomState(rng, X, trial == 4);
    const Mat3 R = CalcPolarRotation(CalcTetDeformationGradient(rest, x));
    const double scale = 0.37;
    TetRestStiffness blocks;
    CalcRotatedTetStiffnessBlocks(rest, kLame, R, scale, blocks);
    const Mat12 expected = scale * CalcFrozenRotationTetStiffness(rest, kLame, R);
    Mat12 K;
    for (int n = 0; n < 4; ++n)
      for (int m = 0; m < 4; ++m) K.block<3, 3>(3 * n, 3 * m) = blocks[4 * n + m];
    EXPECT_LT(RelativeError(K, expected), 1e-14) << "trial " << trial;
    EXPECT_EQ(K, K.transpose()) << "trial " << trial;
  }
}

TEST(CorotatedTetElementTest, RigidMotionHasZeroForceAndEnergy) {
  std::array<Vec3, 4> X;
  const TetRestElement rest = MakeRest(X);
  std::mt19937 rng(6);
  for (int trial = 0; trial < 100; ++trial) {
    const Mat3 Q = testing::RandomRotation(rng);  // large rotations, any angle
    const Vec3 t(3.0 * trial, -1.0, 2.0);
    std::array<Vec3, 4> x;
    for (int n = 0; n < 4; ++n) x[n] = Q * X[n] + t;
    const Mat3 G = CalcTetDeformationGradient(rest, x);
    EXPECT_LT(Forces(rest, Flatten(x)).norm(), 1e-12 * kLame.mu);
    EXPECT_LT(CalcCorotatedTetEnergy(rest, kLame, G, CalcPolarRotation(G)), 1e-12);
  }
}

TEST(CorotatedTetElementTest, PatchTestAffineStretchGivesUniformExactStress) {
  // x = A X with A symmetric (no rotation): every element has sigma = 2 mu eps + lambda tr(eps) I,
  // and interior nodes carry zero net force.
  const TetMesh mesh = MakeBoxTetMesh(Vec3(1, 1, 1), 3, 3, 3);
  TetElementModel model(std::make_shared<TetMesh>(mesh), Material{1e5, 0.3, 1000});
  Mat3 A;
  A << 1.02, 0.01, 0.0, 0.01, 0.97, 0.005, 0.0, 0.005, 1.01;
  VecX x(3 * mesh.nodes.size());
  for (size_t i = 0; i < mesh.nodes.size(); ++i) x.segment<3>(3 * i) = A * mesh.nodes[i];
  VecX f = VecX::Zero(x.size());
  model.UpdateRotationsAndAddForces(x, f);
  const Mat3 eps = A - Mat3::Identity();
  const Mat3 sigma = 2 * kLame.mu * eps + kLame.lambda * eps.trace() * Mat3::Identity();
  for (int e = 0; e < model.num_elements(); ++e) {
    const Mat3 G = CalcTetDeformationGradient(model.rest().elements[e], model.GatherElement(x, e));
    EXPECT_LT((CalcCorotatedStress(kLame, G, model.rotation(e)) - sigma).norm(),
              1e-9 * sigma.norm());
  }
  const Mat3 stress = sigma;
  ASSERT_GT(stress.norm(), 100.0);
  for (int k = 1; k < 3; ++k)
    for (int j = 1; j < 3; ++j)
      for (int i = 1; i < 3; ++i)
        EXPECT_LT(f.segment<3>(3 * BoxNodeIndex(i, j, k, 3, 3)).norm(), 1e-9 * stress.norm());
}

}  // namespace
}  // namespace taut
