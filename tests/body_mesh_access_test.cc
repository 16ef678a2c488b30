// A body gives back its rest mesh and element rest volumes, and writes its current mesh to VTK.
#include <gtest/gtest.h>

#include <fstream>
#include <memory>
#include <sstream>

#include "plugin/box_tet_mesher.h"
#include "plugin/deformable_body.h"
#include "plugin/hex_element_model.h"
#include "plugin/tet_element_model.h"
#include "plugin/vtk_body_writer.h"
#include "plugin/vtk_reader.h"

namespace taut {
namespace {

DeformableBodySettings MakeSettings() {
  DeformableBodySettings settings;
  settings.name = "block";
  settings.material = {1e5, 0.3, 1000.0};
  return settings;
}

std::unique_ptr<DeformableBody> MakeTetBody(const TetMesh& mesh) {
  return std::make_unique<DeformableBody>(
      std::make_unique<TetElementModel>(std::make_shared<const TetMesh>(mesh),
                                        MakeSettings().material),
      MakeSettings());
}

std::unique_ptr<DeformableBody> MakeHexBody(const HexLattice& lattice) {
  return std::make_unique<DeformableBody>(
      std::make_unique<HexElementModel>(std::make_shared<const HexLattice>(lattice),
                                        MakeSettings().material),
      MakeSettings());
}

// Sum of the body's element rest volumes [m^3].
double SumRestVolumes(const DeformableBody& body) {
  double sum = 0.0;
  for (int e = 0; e < body.num_elements(); ++e) {
    EXPECT_GT(body.element_rest_volume(e), 0.0);
    sum += body.element_rest_volume(e);
  }
  return sum;
}

TEST(BodyMeshAccessTest, TetRestVolumesSumToTheBoxVolume) {
  const Vec3 size(0.3, 0.2, 0.5);
  const auto body = MakeTetBody(MakeBoxTetMesh(size, 3, 2, 4, Vec3(1, -2, 0.5)));
  ASSERT_EQ(body->num_elements(), 6 * 3 * 2 * 4);
  const double volume = size.prod();
  EXPECT_NEAR(SumRestVolumes(*body), volume, 1e-12 * volume);
  // Each Kuhn tet is a sixth of its cube.
  EXPECT_NEAR(body->element_rest_volume(7), volume / 144.0, 1e-12 * volume / 144.0);
}

TEST(BodyMeshAccessTest, HexRestVolumesSumToTheBoxVolume) {
  const Vec3 size(0.3, 0.2, 0.5);
  const auto body = MakeHexBody(MakeBoxHexLattice(size, 3, 2, 4, Vec3(1, -2, 0.5)));
  ASSERT_EQ(body->num_elements(), 24);
  EXPECT_NEAR(SumRestVolumes(*body), size.prod(), 1e-12 * size.prod());
}

TEST(BodyMeshAccessTest, BodyGivesBackTheMeshItWasMadeFrom) {
  const TetMesh mesh = MakeBoxTetMesh(Vec3(0.3, 0.2, 0.5), 2, 1, 3);
  const auto tets = MakeTetBody(mesh);
  ASSERT_NE(tets->rest_tet_mesh(), nullptr);
  EXPECT_EQ(tets->rest_tet_mesh()->nodes, mesh.nodes);
  EXPECT_EQ(tets->rest_tet_mesh()->tets, mesh.tets);
  EXPECT_EQ(tets->rest_hex_lattice(), nullptr);
  const HexLattice lattice = MakeBoxHexLattice(Vec3(0.3, 0.2, 0.5), 2, 1, 3);
  const auto hexes = MakeHexBody(lattice);
  ASSERT_NE(hexes->rest_hex_lattice(), nullptr);
  EXPECT_EQ(hexes->rest_hex_lattice()->hexes, lattice.hexes);
  EXPECT_EQ(hexes->rest_tet_mesh(), nullptr);
}

TEST(BodyMeshAccessTest, WrittenTetBodyReadsBackAsItsCurrentPositions) {
  const auto body = MakeTetBody(MakeBoxTetMesh(Vec3(0.4, 0.1, 0.1), 4, 1, 1));
  body->FixNodesWhere([](const Vec3& X) { return X.x() < 1e-9; });
  for (int step = 0; step < 5; ++step) {
    body->BeginStep(1e-2, Vec3(0, 0, -9.81));
    body->EndStep(1e-2);
  }
  ASSERT_NE(body->x(), body->model().rest_positions());  // deformed
  const std::string path = ::testing::TempDir() + "body_mesh_access_tet.vtk";
  WriteVtk(*body, path);
  const TetMesh read = ReadVtkMesh(path);
  ASSERT_EQ(static_cast<int>(read.nodes.size()), body->num_nodes());
  for (int i = 0; i < body->num_nodes(); ++i) EXPECT_EQ(read.nodes[i], body->node_position(i));
  EXPECT_EQ(read.tets, body->rest_tet_mesh()->tets);
}

TEST(BodyMeshAccessTest, WrittenHexBodyHoldsItsCurrentPositionsAndHexahedra) {
  const auto body = MakeHexBody(MakeBoxHexLattice(Vec3(0.4, 0.1, 0.1), 4, 1, 1));
  VecX x = body->x();
  x[3 * 5 + 2] = 0.125;  // node 5 lifted
  body->set_x(x);
  const std::string path = ::testing::TempDir() + "body_mesh_access_hex.vtk";
  WriteVtk(*body, path);
  std::ifstream file(path);
  std::stringstream text;
  text << file.rdbuf();
  const std::string vtk = text.str();
  EXPECT_NE(vtk.find("POINTS 20 double\n"), std::string::npos);
  EXPECT_NE(vtk.find("\n0 0.1 0.125\n"), std::string::npos);  // node 5, rest (0, 0.1, 0)
  EXPECT_NE(vtk.find("CELL_TYPES 4\n12\n12\n12\n12\n"), std::string::npos);
}

}  // namespace
}  // namespace taut
