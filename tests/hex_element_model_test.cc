#include "plugin/hex_element_model.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <string>

#include "plugin/box_tet_mesher.h"
#include "plugin/deformable_body.h"
#include "plugin/tet_element_model.h"
#include "tests/test_utils.h"

namespace taut {
namespace {

using testing::CentralDifference;
using testing::RelativeError;

const Material kMaterial{1e5, 0.3, 1000};

// Message of the InputError thrown by f, or "" when nothing is thrown.
template <typename F>
std::string ErrorOf(F f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(HexLatticeTest, BoxLatticeSharesNodesWithBoxTetMeshAndFollowsCornerSigns) {
  const Vec3 size(1.0, 0.4, 0.6), corner(-1, 2, 0.5);
  const HexLattice lattice = MakeBoxHexLattice(size, 4, 2, 3, corner);
  const TetMesh tets = MakeBoxTetMesh(size, 4, 2, 3, corner);
  ASSERT_EQ(lattice.nodes.size(), tets.nodes.size());
  for (size_t i = 0; i < tets.nodes.size(); ++i) EXPECT_EQ(lattice.nodes[i], tets.nodes[i]);
  ASSERT_EQ(lattice.hexes.size(), 24u);
  const Vec3 half_cell = 0.5 * size.cwiseQuotient(Vec3(4, 2, 3));
  for (const auto& h : lattice.hexes) {
    Vec3 centre = Vec3::Zero();
    for (int a = 0; a < 8; ++a) centre += lattice.nodes[h[a]] / 8.0;
    // Node a sits at centre + half_cell .* s_a (docs/math.md §4.1 ordering).
    for (int a = 0; a < 8; ++a)
      EXPECT_LT((lattice.nodes[h[a]] - centre - half_cell.cwiseProduct(HexCornerSign(a))).norm(),
                1e-12);
  }
  EXPECT_NO_THROW(ValidateHexLattice(lattice));
}

TEST(HexLatticeTest, ValidationNamesTheElement) {
  const HexLattice good = MakeBoxHexLattice(Vec3(1, 1, 1), 2, 2, 1);
  auto check = [&](auto corrupt, const std::string& what) {
    HexLattice bad = good;
    corrupt(bad);
    const std::string msg = ErrorOf([&] { ValidateHexLattice(bad); });
    EXPECT_NE(msg.find(what), std::string::npos) << "got '" << msg << "'";
  };
  check([](HexLattice& l) { l.hexes[3][5] = 99; }, "element 3 refers to node 99");
  check([](HexLattice& l) { l.hexes[2][6] = l.hexes[2][1]; }, "element 2 repeats node");
  check([](HexLattice& l) { l.nodes[4].x() = std::nan(""); }, "node 4 has a non-finite");
  // Mirror element 1 (swap the s1 = -1 and s1 = +1 faces): det F < 0.
  check(
      [](HexLattice& l) {
        for (int a = 0; a < 4; ++a) std::swap(l.hexes[1][a], l.hexes[1][a + 4]);
      },
      "element 1 is inverted");
  // Flatten element 0 by moving its s3 = +1 face onto the s3 = -1 face: det F = 0.
  check(
      [](HexLattice& l) {
        for (int a = 1; a < 8; a += 2) l.nodes[l.hexes[0][a]] = l.nodes[l.hexes[0][a - 1]];
      },
      "element 0 is degenerate");
  check([](HexLattice& l) { l.hexes.clear(); }, "no hexahedra");
  EXPECT_THROW(MakeBoxHexLattice(Vec3(1, 1, 1), 0, 1, 1), InputError);
  EXPECT_THROW(MakeBoxHexLattice(Vec3(1, -1, 1), 1, 1, 1), InputError);
  // The model validates too and names the source.
  auto inverted = std::make_shared<HexLattice>(good);
  for (int a = 0; a < 4; ++a) std::swap(inverted->hexes[2][a], inverted->hexes[2][a + 4]);
  const std::string msg = ErrorOf([&] { HexElementModel model(inverted, kMaterial); });
  EXPECT_NE(msg.find("box hex 2x2x1: element 2 is inverted"), std::string::npos) << msg;
}

TEST(HexElementModelTest, LumpedMassSumsToBodyMass) {
  const HexElementModel model(
      std::make_shared<HexLattice>(MakeBoxHexLattice(Vec3(1, 0.2, 0.3), 4, 2, 2)), kMaterial);
  VecX mass;
  model.CalcLumpedMass(800, mass);
  EXPECT_NEAR(mass.sum(), 800 * 0.06, 1e-12);
  EXPECT_NEAR(mass[0], 800 * 0.06 / 16 / 8, 1e-12);  // corner node: 1/8 of one hex
}

// A 3x3x3 lattice of the unit cube with its interior nodes moved (distorted hexes).
std::shared_ptr<HexLattice> MakeDistortedLattice() {
  auto lattice = std::make_shared<HexLattice>(MakeBoxHexLattice(Vec3(1, 1, 1), 3, 3, 3));
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-0.06, 0.06);
  for (int k = 1; k <= 2; ++k)
    for (int j = 1; j <= 2; ++j)
      for (int i = 1; i <= 2; ++i)
        lattice->nodes[BoxNodeIndex(i, j, k, 3, 3)] += Vec3(u(rng), u(rng), u(rng));
  return lattice;
}

TEST(HexElementModelTest, StiffnessIsMinusForceJacobianWithFrozenRotations) {
  HexElementModel model(MakeDistortedLattice(), kMaterial);
  const int n = 3 * model.num_nodes();
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> u(-0.03, 0.03);
  const Mat3 Q = testing::RandomRotation(rng);
  VecX x(n);
  for (int i = 0; i < model.num_nodes(); ++i)
    x.segment<3>(3 * i) =
        Q * model.rest_positions().segment<3>(3 * i) + Vec3(u(rng), u(rng), u(rng));
  VecX f = VecX::Zero(n);
  const double energy = model.UpdateRotationsAndAddForces(x, f);
  EXPECT_NEAR(energy, model.CalcEnergy(x), 1e-12 * energy);
  // Forces with the rotations of the update frozen, from the element kernels.
  auto frozen_forces = [&](const VecX& q) {
    VecX out = VecX::Zero(n);
    for (int e = 0; e < model.num_elements(); ++e) {
      const Vec24 fe =
          CalcCorotatedHexForces(model.rest(e), model.GatherElement(q, e), model.rotation(e));
      for (int a = 0; a < 8; ++a)
        out.segment<3>(3 * model.element_nodes(e)[a]) += fe.segment<3>(3 * a);
    }
    return out;
  };
  EXPECT_LT((frozen_forces(x) - f).norm(), 1e-12 * f.norm());
  const MatX J = CentralDifference(frozen_forces, x, 1e-6);
  // Dense K via the index map layout of element_model.h (value index = column-major dense index).
  std::vector<int> map;
  for (int e = 0; e < model.num_elements(); ++e)
    for (int a = 0; a < 8; ++a)
      for (int b = 0; b < 8; ++b)
        for (int c = 0; c < 3; ++c)
          for (int r = 0; r < 3; ++r)
            map.push_back((3 * model.element_nodes(e)[b] + c) * n + 3 * model.element_nodes(e)[a] +
                          r);
  MatX K = MatX::Zero(n, n);
  model.AddScaledStiffness(2.0, map, K.data());
  ASSERT_GT(J.norm(), 1e3);
  EXPECT_LT(RelativeError(0.5 * K, -J), 1e-8);
  // Matrix-free product agrees with the assembled matrix.
  const VecX v = VecX::Random(n);
  VecX Kv = VecX::Ones(n);
  model.AddScaledStiffnessTimes(3.0, v, Kv);
  EXPECT_LT((Kv - VecX::Ones(n) - 1.5 * K * v).norm(), 1e-10 * Kv.norm());
}

TEST(HexElementModelTest, PatchTestGivesUniformStressAndBalancedInteriorNodes) {
  // x = Q A X with A symmetric positive definite: polar(G(0)) = Q, every Gauss point carries
  // eps = A - I, sigma = 2 mu eps + lambda tr(eps) I, and interior nodes feel zero net force,
  // also on the distorted lattice.
  HexElementModel model(MakeDistortedLattice(), kMaterial);
  Mat3 A;
  A << 1.02, 0.01, -0.005, 0.01, 0.97, 0.015, -0.005, 0.015, 1.01;
  std::mt19937 rng(13);
  const Mat3 Q = testing::RandomRotation(rng);
  const int n = 3 * model.num_nodes();
  VecX x(n);
  for (int i = 0; i < model.num_nodes(); ++i)
    x.segment<3>(3 * i) = Q * A * model.rest_positions().segment<3>(3 * i) + Vec3(0.1, 0.2, 0.3);
  VecX f = VecX::Zero(n);
  model.UpdateRotationsAndAddForces(x, f);
  const LameParameters& lame = model.lame();
  const Mat3 eps = A - Mat3::Identity();
  const Mat3 sigma = 2 * lame.mu * eps + lame.lambda * eps.trace() * Mat3::Identity();
  for (int e = 0; e < model.num_elements(); ++e) {
    EXPECT_LT((model.rotation(e) - Q).norm(), 1e-12) << "element " << e;
    for (int q = 0; q < 8; ++q) {
      const Mat3 eq =
          CalcHexGaussStrain(model.rest(e), model.GatherElement(x, e), model.rotation(e), q);
      const Mat3 sq = 2 * lame.mu * eq + lame.lambda * eq.trace() * Mat3::Identity();
      EXPECT_LT((sq - sigma).norm(), 1e-9 * sigma.norm()) << "element " << e << " point " << q;
    }
  }
  double interior = 0.0;
  for (int k = 1; k <= 2; ++k)
    for (int j = 1; j <= 2; ++j)
      for (int i = 1; i <= 2; ++i) interior += f.segment<3>(3 * BoxNodeIndex(i, j, k, 3, 3)).norm();
  ASSERT_GT(f.norm(), 1e2);
  EXPECT_LT(interior, 1e-10 * f.norm());
  // Boundary: the nodes of the face x = 1 (area 1) hold the internal force -Q sigma e1 (the
  // strips of the faces y = 0, 1 and z = 0, 1 cancel in pairs).
  Vec3 face = Vec3::Zero();
  for (int i = 0; i < model.num_nodes(); ++i)
    if (model.rest_positions()[3 * i] > 1 - 1e-9) face += f.segment<3>(3 * i);
  EXPECT_LT((face + Q * sigma.col(0)).norm(), 1e-9 * sigma.norm());
}

// Beam L x H x H fixed at x = 0, meshed nx x 2 x nz as hexes (or the same grid as 6-tet cubes).
std::unique_ptr<DeformableBody> MakeBeam(double L, double H, int nx, int nz, const Material& m,
                                         bool hex) {
  DeformableBodySettings settings;
  settings.name = hex ? "hex beam" : "tet beam";
  settings.material = m;
  const Vec3 size(L, H, H);
  std::unique_ptr<ElementModel> model;
  if (hex)
    model = std::make_unique<HexElementModel>(
        std::make_shared<HexLattice>(MakeBoxHexLattice(size, nx, 2, nz)), m);
  else
    model = std::make_unique<TetElementModel>(
        std::make_shared<TetMesh>(MakeBoxTetMesh(size, nx, 2, nz)), m);
  auto body = std::make_unique<DeformableBody>(std::move(model), settings);
  body->FixNodesWhere([](const Vec3& X) { return X.x() < 1e-9; });
  return body;
}

// Static tip deflection under gravity (mean -z displacement at x = L) from large-h backward-Euler
// steps, which are Newton steps of the static problem (as in deformable_body_test.cc).
double StaticTip(DeformableBody& body, double L) {
  for (int it = 0; it < 2; ++it) {
    body.set_v(VecX::Zero(body.x().size()));
    body.BeginStep(1e3, Vec3(0, 0, -9.81));
    body.EndStep(1e3);
  }
  double sum = 0.0;
  int count = 0;
  for (int i = 0; i < body.num_nodes(); ++i) {
    const Vec3 X = body.model().rest_positions().segment<3>(3 * i);
    if (X.x() > L - 1e-9) {
      sum += body.node_position(i).z() - X.z();
      ++count;
    }
  }
  return -sum / count;
}

TEST(HexElementModelTest, StaticCantileverMatchesTimoshenkoWithin5Percent) {
  // L/H = 5, nu = 0. Trilinear hexes shear-lock in bending by about 2 (l/H)^2 for element length
  // l, so the beam is cut finely along x (40 x 2 x 4 hexes, l/H = 1/8).
  const double L = 1.0, H = 0.2, E = 1e8, nu = 0.0, rho = 1000, g = 9.81;
  const Material material{E, nu, rho};
  const double A = H * H, I = H * H * H * H / 12.0, q = rho * g * A;
  const double G = E / (2 * (1 + nu)), kappa = 10 * (1 + nu) / (12 + 11 * nu);
  const double expected = q * std::pow(L, 4) / (8 * E * I) + q * L * L / (2 * kappa * G * A);
  const auto start = std::chrono::steady_clock::now();
  auto coarse = MakeBeam(L, H, 5, 2, material, true);
  auto fine = MakeBeam(L, H, 40, 4, material, true);
  const double tip_coarse = StaticTip(*coarse, L), tip = StaticTip(*fine, L);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::printf(
      "hex cantilever tip: 5x2x2 %.4e m, 40x2x4 %.4e m, Timoshenko %.4e m (error %.2f %%), "
      "%.0f ms\n",
      tip_coarse, tip, expected, 100 * (tip / expected - 1), ms);
  EXPECT_NEAR(tip / expected, 1.0, 0.05);
  EXPECT_LT(tip_coarse, 0.9 * tip);  // coarse elements (l/H = 1) lock visibly
}

TEST(HexElementModelTest, RefinedHexAndTetCantileversAgreeWithEachOtherAndBeamTheory) {
  // Refined meshes of the same L/H = 5, nu = 0 beam: hexes 40 x 2 x 4, tets 80 x 2 x 16 cubes.
  const double L = 1.0, H = 0.2, E = 1e8, nu = 0.0, rho = 1000;
  const Material material{E, nu, rho};
  const double A = H * H, I = H * H * H * H / 12.0, q = rho * 9.81 * A;
  const double G = E / (2 * (1 + nu)), kappa = 10 * (1 + nu) / (12 + 11 * nu);
  const double timoshenko = q * std::pow(L, 4) / (8 * E * I) + q * L * L / (2 * kappa * G * A);
  auto hex = MakeBeam(L, H, 40, 4, material, true);
  auto tet = MakeBeam(L, H, 80, 16, material, false);
  const double tip_hex = StaticTip(*hex, L), tip_tet = StaticTip(*tet, L);
  std::printf("refined cantilevers: hex %.4e m, tet %.4e m, Timoshenko %.4e m\n", tip_hex, tip_tet,
              timoshenko);
  EXPECT_NEAR(tip_hex / tip_tet, 1.0, 0.05);
  EXPECT_NEAR(tip_hex / timoshenko, 1.0, 0.05);
  EXPECT_NEAR(tip_tet / timoshenko, 1.0, 0.05);
}

TEST(HexElementModelTest, HexBeamLocksLessThanTetBeamAtNearIncompressibility) {
  // Same grid (same nodes), nu = 0.45: the 6-tet split locks volumetrically, hexes much less.
  const double L = 1.0, H = 0.2;
  const Material material{1e8, 0.45, 1000};
  auto hex = MakeBeam(L, H, 20, 4, material, true);
  auto tet = MakeBeam(L, H, 20, 4, material, false);
  ASSERT_EQ(hex->num_nodes(), tet->num_nodes());
  const double tip_hex = StaticTip(*hex, L), tip_tet = StaticTip(*tet, L);
  std::printf("nu = 0.45, 20x2x4 grid (%d nodes): hex tip %.4e m, tet tip %.4e m, ratio %.3f\n",
              hex->num_nodes(), tip_hex, tip_tet, tip_hex / tip_tet);
  EXPECT_GT(tip_hex, 1.3 * tip_tet);
}

}  // namespace
}  // namespace taut
