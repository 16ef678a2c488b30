#include "plugin/hex_shapes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "plugin/corotated_hex_element.h"

namespace taut {
namespace {

// Sum of the hexes' rest volumes (Gauss rule, exact for trilinear hexes) [m^3].
double CalcLatticeVolume(const HexLattice& lattice) {
  double volume = 0.0;
  for (const auto& hex : lattice.hexes) {
    HexNodes X;
    for (int a = 0; a < 8; ++a) X[a] = lattice.nodes[hex[a]];
    volume += CalcHexRestElement(X, {1.0, 1.0}).volume;
  }
  return volume;
}

// Every node is used by some hex (compacted numbering).
void ExpectEveryNodeUsed(const HexLattice& lattice) {
  std::set<int> used;
  for (const auto& hex : lattice.hexes) used.insert(hex.begin(), hex.end());
  EXPECT_EQ(used.size(), lattice.nodes.size());
}

TEST(HexShapesTest, CylinderVolumeBoundsAndValidity) {
  const double length = 2.0, radius = 0.5;
  const HexLattice lattice = MakeCylinderHexLattice(length, radius, 0.05, Vec3(1.0, 2.0, 3.0));
  EXPECT_NO_THROW(ValidateHexLattice(lattice));
  ExpectEveryNodeUsed(lattice);
  const double exact = M_PI * radius * radius * length;
  EXPECT_NEAR(CalcLatticeVolume(lattice), exact, 0.03 * exact);
  // Cells 0.05 m: 40 along x; all nodes in [start, start + length] x disc-ish cross-section.
  double x_min = 1e9, x_max = -1e9;
  for (const Vec3& p : lattice.nodes) {
    x_min = std::min(x_min, p.x());
    x_max = std::max(x_max, p.x());
    EXPECT_LE((p - Vec3(p.x(), 2.0, 3.0)).norm(), radius + 0.05 * std::sqrt(0.5) + 1e-12);
  }
  EXPECT_NEAR(x_min, 1.0, 1e-12);
  EXPECT_NEAR(x_max, 3.0, 1e-12);
  EXPECT_EQ(lattice.hexes.size() % 40, 0u);
}

TEST(HexShapesTest, PaperBBeamHas56Hexes) {
  // 1 m x 12 cm cylinder with cell size 1/14 m: 14 x 2 x 2 cells, all four centres inside.
  const HexLattice lattice = MakeCylinderHexLattice(1.0, 0.06, 1.0 / 14.0);
  EXPECT_NO_THROW(ValidateHexLattice(lattice));
  EXPECT_EQ(lattice.hexes.size(), 56u);
  EXPECT_EQ(lattice.nodes.size(), 15u * 9u);
  EXPECT_NEAR(CalcLatticeVolume(lattice), 0.12 * 0.12 * 1.0, 1e-12);
}

TEST(HexShapesTest, SphereVolumeAndValidity) {
  const double radius = 1.0;
  const HexLattice lattice = MakeSphereHexLattice(radius, 0.1, Vec3(-1.0, 0.5, 2.0));
  EXPECT_NO_THROW(ValidateHexLattice(lattice));
  ExpectEveryNodeUsed(lattice);
  const double exact = 4.0 / 3.0 * M_PI;
  EXPECT_NEAR(CalcLatticeVolume(lattice), exact, 0.03 * exact);
  Vec3 mean = Vec3::Zero();
  for (const Vec3& p : lattice.nodes) mean += p;
  mean /= static_cast<double>(lattice.nodes.size());
  EXPECT_LT((mean - Vec3(-1.0, 0.5, 2.0)).norm(), 1e-9);  // symmetric about the centre
}

TEST(HexShapesTest, BadSizesThrow) {
  EXPECT_THROW(MakeCylinderHexLattice(0.0, 0.1, 0.1), InputError);
  EXPECT_THROW(MakeCylinderHexLattice(1.0, -0.1, 0.1), InputError);
  EXPECT_THROW(MakeSphereHexLattice(1.0, std::nan("")), InputError);
  try {
    MakeSphereHexLattice(1.0, 0.0);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("sphere hex lattice: cell size = 0"),
              std::string::npos)
        << error.what();
  }
  // A 1-cell grid over a sphere keeps its one cell (centre = sphere centre).
  EXPECT_EQ(MakeSphereHexLattice(1.0, 5.0).hexes.size(), 1u);
}

}  // namespace
}  // namespace taut
