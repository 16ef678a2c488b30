#include "plugin/hex_voxelizer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace taut {
namespace {

// Generalized winding number (1 / 4 pi) sum_t Omega_t(p) of a closed surface around p, with the
// solid angle of each triangle by Van Oosterom and Strackee (1983): an inside test independent of
// the voxelizer's ray casting.
double CalcWindingNumber(const SurfaceMesh& mesh, const Vec3& p) {
  double sum = 0.0;
  for (const Triangle& t : mesh.triangles) {
    const Vec3 a = mesh.vertices[t[0]] - p, b = mesh.vertices[t[1]] - p,
               c = mesh.vertices[t[2]] - p;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    sum += 2.0 * std::atan2(a.dot(b.cross(c)),
                            la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb);
  }
  return sum / (4.0 * M_PI);
}

// Centre of hex e (mean of its 8 nodes).
Vec3 HexCentre(const HexLattice& lattice, int e) {
  Vec3 c = Vec3::Zero();
  for (int n : lattice.hexes[e]) c += lattice.nodes[n] / 8.0;
  return c;
}

// Appends b's vertices and triangles to a.
void Append(SurfaceMesh& a, const SurfaceMesh& b, bool invert) {
  const int offset = static_cast<int>(a.vertices.size());
  a.vertices.insert(a.vertices.end(), b.vertices.begin(), b.vertices.end());
  for (Triangle t : b.triangles) {
    for (int& i : t) i += offset;
    if (invert) std::swap(t[1], t[2]);
    a.triangles.push_back(t);
  }
}

TEST(HexVoxelizerTest, SphereAtEighthRadiusHasTheSphereVolumeAndCentresInside) {
  const double R = 0.8;
  const Vec3 centre(0.1, -0.3, 2.0);
  const SurfaceMesh sphere = MakeIcosphereSurface(R, 5, centre);
  const double h = R / 8;
  const HexLattice lattice = VoxelizeSurface(sphere, h);
  EXPECT_NO_THROW(ValidateHexLattice(lattice));
  const double exact = 4.0 / 3.0 * M_PI * R * R * R;
  const double volume = lattice.hexes.size() * h * h * h;
  RecordProperty("sphere_hexes", static_cast<int>(lattice.hexes.size()));
  EXPECT_NEAR(volume / exact, 1.0, 0.03) << lattice.hexes.size() << " hexes";
  for (int e = 0; e < static_cast<int>(lattice.hexes.size()); ++e) {
    EXPECT_LT((HexCentre(lattice, e) - centre).norm(), R) << "hex " << e;
    // Cubic cell of edge h in the local node order: node a at node 0 + h (bi, bj, bk).
    const Vec3& X0 = lattice.nodes[lattice.hexes[e][0]];
    for (int a = 0; a < 8; ++a)
      EXPECT_LT(
          (lattice.nodes[lattice.hexes[e][a]] - X0 - h * (HexCornerSign(a) + Vec3::Ones()) / 2)
              .norm(),
          1e-12);
  }
  // Nodes are shared: a compact lattice has fewer nodes than 8 per hex and uses every node.
  std::vector<int> uses(lattice.nodes.size(), 0);
  for (const auto& hex : lattice.hexes)
    for (int n : hex) ++uses[n];
  for (std::size_t n = 0; n < uses.size(); ++n) EXPECT_GT(uses[n], 0) << "node " << n;
  EXPECT_LT(lattice.nodes.size(), 2 * lattice.hexes.size());
  // The procedural overload with the exact sphere keeps nearly the same cells.
  const HexLattice exact_lattice = VoxelizeSurface(
      [&](const Vec3& p) { return (p - centre).norm() < R; }, CalcSurfaceBounds(sphere), h);
  EXPECT_NEAR(static_cast<double>(exact_lattice.hexes.size()), lattice.hexes.size(),
              0.02 * lattice.hexes.size());
}

TEST(HexVoxelizerTest, KeptCellsAreExactlyTheCellsWithCentresOfWindingNumberOne) {
  // A coarse icosphere, off-centre grid: compare every grid cell with the winding number.
  const SurfaceMesh sphere = MakeIcosphereSurface(1.0, 2, Vec3(0.013, 0.21, -0.07));
  const double h = 0.23;
  const HexLattice lattice = VoxelizeSurface(sphere, h);
  // Rebuild the grid from the documented rule and count cells with winding number ~1.
  const Eigen::AlignedBox3d bounds = CalcSurfaceBounds(sphere);
  Vec3 n;
  for (int d = 0; d < 3; ++d) n[d] = std::ceil(bounds.sizes()[d] / h * (1 - 1e-9));
  const Vec3 origin = bounds.center() - 0.5 * h * n;
  int inside = 0;
  for (int k = 0; k < n.z(); ++k)
    for (int j = 0; j < n.y(); ++j)
      for (int i = 0; i < n.x(); ++i) {
        const double w = CalcWindingNumber(sphere, origin + h * Vec3(i + 0.5, j + 0.5, k + 0.5));
        ASSERT_TRUE(std::abs(w) < 1e-6 || std::abs(w - 1) < 1e-6) << w;
        inside += w > 0.5;
      }
  EXPECT_GT(inside, 100);
  EXPECT_EQ(static_cast<int>(lattice.hexes.size()), inside);
  for (int e = 0; e < static_cast<int>(lattice.hexes.size()); ++e)
    EXPECT_NEAR(CalcWindingNumber(sphere, HexCentre(lattice, e)), 1.0, 1e-6) << "hex " << e;
}

TEST(HexVoxelizerTest, GridAlignedBoxGivesExactlyItsCellsEvenWhenRaysHitDiagonals) {
  // Every cell centre line meets the triangulated faces exactly on a diagonal (1x1 faces) or a
  // quad diagonal (4x3x2 faces): the perturbation must count each crossing once.
  for (const Vec3& corner : {Vec3(0, 0, 0), Vec3(-0.3, 0.1, 0.7)}) {
    for (int split : {1, 0}) {
      const Vec3 size(1.0, 0.75, 0.5);
      const SurfaceMesh box =
          split ? MakeBoxSurface(size, 4, 3, 2, corner) : MakeBoxSurface(size, 1, 1, 1, corner);
      for (const double h : {0.25, 0.125}) {
        const HexLattice lattice = VoxelizeSurface(box, h);
        const int expected = static_cast<int>(std::lround(size.prod() / (h * h * h)));
        EXPECT_EQ(static_cast<int>(lattice.hexes.size()), expected) << "h " << h;
        const int nx = static_cast<int>(std::lround(size.x() / h)),
                  ny = static_cast<int>(std::lround(size.y() / h)),
                  nz = static_cast<int>(std::lround(size.z() / h));
        EXPECT_EQ(static_cast<int>(lattice.nodes.size()), (nx + 1) * (ny + 1) * (nz + 1));
        // The lattice is the box: nodes span it exactly (up to round-off of the centring).
        Eigen::AlignedBox3d span;
        for (const Vec3& X : lattice.nodes) span.extend(X);
        EXPECT_LT((span.min() - corner).norm(), 1e-12);
        EXPECT_LT((span.max() - corner - size).norm(), 1e-12);
        EXPECT_NO_THROW(ValidateHexLattice(lattice));
      }
    }
  }
  // An inverted (inward-wound) box still voxelizes: the winding number is -1 inside.
  SurfaceMesh inverted = MakeBoxSurface(Vec3(1, 1, 1), 1, 1, 1);
  for (Triangle& t : inverted.triangles) std::swap(t[1], t[2]);
  EXPECT_EQ(VoxelizeSurface(inverted, 0.5).hexes.size(), 8u);
}

TEST(HexVoxelizerTest, HollowBoxKeepsOnlyTheShell) {
  // Outer box [0, 1]^3 and an inward-wound inner box [0.25, 0.75]^3: the cavity has winding 0.
  SurfaceMesh hollow = MakeBoxSurface(Vec3(1, 1, 1), 1, 1, 1);
  Append(hollow, MakeBoxSurface(Vec3(0.5, 0.5, 0.5), 1, 1, 1, Vec3(0.25, 0.25, 0.25)), true);
  EXPECT_EQ(VoxelizeSurface(hollow, 0.25).hexes.size(), 64u - 8u);
  // With one cell its centre lies in the cavity: nothing is kept.
  try {
    VoxelizeSurface(hollow, 1.0);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(hollow.source + ": no cell centre lies inside"),
              std::string::npos)
        << e.what();
  }
}

TEST(HexVoxelizerTest, BadArgumentsThrowInputError) {
  const SurfaceMesh box = MakeBoxSurface(Vec3(1, 1, 1), 1, 1, 1);
  for (const double h : {0.0, -0.1, double(NAN), double(INFINITY)})
    EXPECT_THROW(VoxelizeSurface(box, h), InputError);
  EXPECT_THROW(VoxelizeSurface(box, 1e-4), InputError);  // 1e12 cells
  SurfaceMesh open = box;
  open.triangles.pop_back();
  EXPECT_THROW(VoxelizeSurface(open, 0.5), InputError);
  const auto nothing = [](const Vec3&) { return false; };
  EXPECT_THROW(VoxelizeSurface(nothing, CalcSurfaceBounds(box), 0.5), InputError);
  EXPECT_THROW(VoxelizeSurface(std::function<bool(const Vec3&)>(), CalcSurfaceBounds(box), 0.5),
               InputError);
  EXPECT_THROW(VoxelizeSurface([](const Vec3&) { return true; }, Eigen::AlignedBox3d(), 0.5),
               InputError);
}

}  // namespace
}  // namespace taut
