#include "plugin/surface_mesh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>

namespace taut {
namespace {

// Expects ValidateClosedSurface to throw InputError whose message contains every part.
void ExpectInvalid(const SurfaceMesh& mesh, std::initializer_list<std::string> parts) {
  try {
    ValidateClosedSurface(mesh);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    for (const std::string& part : parts)
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos)
          << e.what() << "\n  expected: " << part;
  }
}

// Two tetrahedron surfaces (0, 1, 2, 3) and (0, 1, 4, 5) that share only the edge (0, 1).
SurfaceMesh MakeBowtie() {
  SurfaceMesh mesh;
  mesh.source = "bowtie";
  mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0, -1, 0}, {0, 0, -1}};
  const auto add_tet = [&](int a, int b, int c, int d) {  // faces outward when det > 0
    mesh.triangles.push_back({a, c, b});
    mesh.triangles.push_back({a, b, d});
    mesh.triangles.push_back({a, d, c});
    mesh.triangles.push_back({b, c, d});
  };
  add_tet(0, 1, 2, 3);
  add_tet(0, 1, 5, 4);
  return mesh;
}

TEST(SurfaceMeshTest, BoxSurfaceIsClosedOutwardAndHasTheBoxVolume) {
  const Vec3 size(1.3, 0.7, 0.5), corner(-0.2, 0.1, 1.0);
  const SurfaceMesh box = MakeBoxSurface(size, 3, 2, 1, corner);
  EXPECT_NO_THROW(ValidateClosedSurface(box));
  // 2 (nx ny + ny nz + nz nx) quads, 2 triangles each; Euler V - E + F = 2.
  EXPECT_EQ(box.triangles.size(), 2u * 2 * (6 + 2 + 3));
  const int V = static_cast<int>(box.vertices.size()), F = static_cast<int>(box.triangles.size());
  EXPECT_EQ(V - 3 * F / 2 + F, 2);
  EXPECT_NEAR(CalcSurfaceSignedVolume(box), size.prod(), 1e-14);
  const Eigen::AlignedBox3d bounds = CalcSurfaceBounds(box);
  EXPECT_TRUE(bounds.min().isApprox(corner, 1e-15));
  EXPECT_TRUE(bounds.max().isApprox(corner + size, 1e-15));
}

TEST(SurfaceMeshTest, IcosphereIsClosedOutwardOnTheSphereAndApproachesItsVolume) {
  const Vec3 centre(0.3, -0.2, 0.1);
  double last_error = 1.0;
  for (int level = 0; level <= 4; ++level) {
    const SurfaceMesh sphere = MakeIcosphereSurface(2.0, level, centre);
    EXPECT_NO_THROW(ValidateClosedSurface(sphere));
    EXPECT_EQ(sphere.triangles.size(), 20u << (2 * level));
    for (const Vec3& v : sphere.vertices) EXPECT_NEAR((v - centre).norm(), 2.0, 1e-14);
    const double error = 1.0 - CalcSurfaceSignedVolume(sphere) / (4.0 / 3.0 * M_PI * 8.0);
    EXPECT_GT(error, 0.0);  // inscribed polyhedron: outward wound and smaller than the sphere
    EXPECT_LT(error, last_error / 2.0);  // O(edge^2): ratio -> 1/4
    last_error = error;
  }
  EXPECT_LT(last_error, 0.005);
}

TEST(SurfaceMeshTest, OpenSurfaceIsRejectedNamingAnEdgeOfTheHole) {
  SurfaceMesh box = MakeBoxSurface(Vec3(1, 1, 1), 2, 2, 2);
  const Triangle removed = box.triangles[5];
  box.triangles.erase(box.triangles.begin() + 5);
  // The neighbours keep the reversed edges of the hole; the smallest is reported first.
  const auto reversed =
      std::min({std::make_pair(removed[1], removed[0]), std::make_pair(removed[2], removed[1]),
                std::make_pair(removed[0], removed[2])});
  ExpectInvalid(box, {box.source + ": edge (" + std::to_string(reversed.first) + ", " +
                          std::to_string(reversed.second) + ")",
                      "the surface is open"});
}

TEST(SurfaceMeshTest, FlippedTriangleAndNonManifoldEdgeAreRejected) {
  SurfaceMesh flipped = MakeBoxSurface(Vec3(1, 1, 1), 1, 1, 1);
  std::swap(flipped.triangles[3][1], flipped.triangles[3][2]);
  ExpectInvalid(flipped, {"is used in the same direction by triangles"});

  ExpectInvalid(MakeBowtie(),
                {"bowtie: edge (0, 1) is used in the same direction", "non-manifold"});
  SurfaceMesh one_tet = MakeBowtie();
  one_tet.triangles.resize(4);
  EXPECT_NO_THROW(ValidateClosedSurface(one_tet));
  EXPECT_NEAR(CalcSurfaceSignedVolume(one_tet), 1.0 / 6.0, 1e-15);

  SurfaceMesh doubled = one_tet;  // a second copy of a face: edge used twice each way
  doubled.triangles.push_back(doubled.triangles[0]);
  ExpectInvalid(doubled, {"used in the same direction by triangles 0 and 4"});
}

TEST(SurfaceMeshTest, BadTrianglesAndVerticesAreRejectedByIndex) {
  SurfaceMesh tet = MakeBowtie();
  tet.triangles.resize(4);
  SurfaceMesh bad = tet;
  bad.triangles[2][1] = 6;
  ExpectInvalid(bad, {"bowtie: triangle 2 refers to vertex 6 but the surface has 6 vertices"});
  bad = tet;
  bad.triangles[1][2] = -1;
  ExpectInvalid(bad, {"triangle 1 refers to vertex -1"});
  bad = tet;
  bad.triangles[3] = {1, 2, 1};
  ExpectInvalid(bad, {"triangle 3 repeats vertex 1"});
  bad = tet;
  bad.vertices[3] = Vec3(0.5, 0.0, 0.0);  // face (0, 1, 3): vertex 3 on edge (0, 1)
  ExpectInvalid(bad, {"triangle 1 (0, 1, 3) is degenerate"});
  bad = tet;
  bad.vertices[4].y() = NAN;
  ExpectInvalid(bad, {"vertex 4 has a non-finite coordinate"});
  ExpectInvalid(SurfaceMesh{}, {"surface: surface has no vertices"});
  SurfaceMesh no_triangles = tet;
  no_triangles.triangles.clear();
  ExpectInvalid(no_triangles, {"has no triangles"});
  EXPECT_THROW(CalcSurfaceBounds(SurfaceMesh{}), InputError);
}

TEST(SurfaceMeshTest, GeneratorsRejectBadArguments) {
  EXPECT_THROW(MakeBoxSurface(Vec3(1, 0, 1), 1, 1, 1), InputError);
  EXPECT_THROW(MakeBoxSurface(Vec3(1, 1, 1), 1, 0, 1), InputError);
  EXPECT_THROW(MakeIcosphereSurface(-1.0, 1), InputError);
  EXPECT_THROW(MakeIcosphereSurface(1.0, 8), InputError);
  EXPECT_THROW(MakeIcosphereSurface(NAN, 1), InputError);
}

}  // namespace
}  // namespace taut
