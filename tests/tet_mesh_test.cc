#include "plugin/tet_mesh.h"

#include <gtest/gtest.h>

#include "plugin/box_tet_mesher.h"

namespace taut {
namespace {

TEST(BoxTetMesherTest, CountsVolumeAndConformingBoundary) {
  const TetMesh mesh = MakeBoxTetMesh(Vec3(1.0, 0.2, 0.3), 5, 2, 3);
  EXPECT_EQ(mesh.nodes.size(), 6u * 3u * 4u);
  EXPECT_EQ(mesh.tets.size(), 6u * 5u * 2u * 3u);
  double volume = 0.0;
  for (const auto& t : mesh.tets) {
    const double v =
        CalcTetSignedVolume(mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]], mesh.nodes[t[3]]);
    EXPECT_GT(v, 0.0);
    volume += v;
  }
  EXPECT_NEAR(volume, 0.06, 1e-14);
  // Conforming: only the outer box faces are boundary, 2 triangles per outer cell face.
  const auto faces = CalcBoundaryFaces(mesh);
  EXPECT_EQ(faces.size(), 2u * 2u * (5 * 2 + 2 * 3 + 5 * 3));
  // Outward winding: the divergence theorem gives the volume back, sum (c . n) A / 3.
  double flux = 0.0;
  for (const auto& f : faces) {
    const Vec3 &a = mesh.nodes[f[0]], &b = mesh.nodes[f[1]], &c = mesh.nodes[f[2]];
    flux += ((a + b + c) / 3.0).dot(0.5 * (b - a).cross(c - a)) / 3.0;
  }
  EXPECT_NEAR(flux, 0.06, 1e-12);
  EXPECT_EQ(CalcBoundaryNodes(mesh).size(), mesh.nodes.size() - 4u * 1u * 2u);
}

TEST(TetMeshValidationTest, RejectsBadElementsNamingThem) {
  TetMesh mesh = MakeBoxTetMesh(Vec3(1, 1, 1), 1, 1, 1);
  mesh.source = "cube.msh";
  EXPECT_NO_THROW(ValidateTetMesh(mesh));
  TetMesh inverted = mesh;
  std::swap(inverted.tets[3][0], inverted.tets[3][1]);
  try {
    ValidateTetMesh(inverted);
    FAIL() << "inverted element accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cube.msh: element 3 is inverted"), std::string::npos)
        << e.what();
  }
  TetMesh flat = mesh;
  flat.nodes.push_back(Vec3(0.5, 0.5, 0.0));
  flat.nodes.push_back(Vec3(0.7, 0.2, 0.0));
  flat.tets.push_back(
      {0, 1, static_cast<int>(flat.nodes.size()) - 2, static_cast<int>(flat.nodes.size()) - 1});
  EXPECT_THROW(ValidateTetMesh(flat), InputError);
  TetMesh out_of_range = mesh;
  out_of_range.tets[0][2] = 99;
  try {
    ValidateTetMesh(out_of_range);
    FAIL() << "index out of range accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("element 0 refers to node 99"), std::string::npos);
  }
  TetMesh nan = mesh;
  nan.nodes[2].x() = std::nan("");
  EXPECT_THROW(ValidateTetMesh(nan), InputError);
}

}  // namespace
}  // namespace taut
