#include "plugin/vtk_hex_writer.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

namespace taut {
namespace {

// Whole file as text.
std::string ReadText(const std::string& path) {
  std::ifstream file(path);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

TEST(VtkHexWriterTest, WritesHexahedraInVtkCornerOrder) {
  // Two unit-box hexes side by side along x, nodes numbered as MakeBoxHexLattice.
  const HexLattice lattice = MakeBoxHexLattice(Vec3(2.0, 1.0, 1.0), 2, 1, 1);
  std::vector<Vec3> moved = lattice.nodes;
  for (Vec3& p : moved) p += Vec3(0.5, 0.0, 0.0);
  const std::string path = ::testing::TempDir() + "/vtk_hex_writer_test.vtk";
  WriteVtkHexLattice(path, lattice, &moved);
  std::istringstream in(ReadText(path));
  std::string line, word;
  std::getline(in, line);
  EXPECT_EQ(line, "# vtk DataFile Version 3.0");
  while (in >> word && word != "POINTS") {
  }
  int num_points = 0;
  in >> num_points >> word;
  ASSERT_EQ(num_points, static_cast<int>(lattice.nodes.size()));
  std::vector<Vec3> points(num_points);
  for (Vec3& p : points) in >> p.x() >> p.y() >> p.z();
  EXPECT_EQ(points, moved);
  int num_cells = 0, size = 0;
  in >> word >> num_cells >> size;
  ASSERT_EQ(word, "CELLS");
  ASSERT_EQ(num_cells, 2);
  EXPECT_EQ(size, 18);
  // VTK's reference corners: bottom face counter-clockwise, then the top face.
  const Vec3 vtk_corner[8] = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0),
                              Vec3(0, 0, 1), Vec3(1, 0, 1), Vec3(1, 1, 1), Vec3(0, 1, 1)};
  for (int c = 0; c < num_cells; ++c) {
    int npts = 0;
    in >> npts;
    ASSERT_EQ(npts, 8);
    std::array<int, 8> conn;
    for (int& i : conn) in >> i;
    const Vec3 origin = points[conn[0]];
    for (int v = 0; v < 8; ++v) {
      EXPECT_EQ(conn[v], lattice.hexes[c][kVtkHexFromLocal[v]]);
      EXPECT_LT((points[conn[v]] - origin - vtk_corner[v]).norm(), 1e-12) << "cell " << c;
    }
  }
  in >> word >> num_cells;
  EXPECT_EQ(word, "CELL_TYPES");
  for (int c = 0; c < num_cells; ++c) {
    int type = 0;
    in >> type;
    EXPECT_EQ(type, kVtkHexahedron);
  }
}

TEST(VtkHexWriterTest, PermutationIsABijection) {
  std::array<int, 8> seen{};
  for (int v = 0; v < 8; ++v) ++seen[kVtkHexFromLocal[v]];
  for (int a = 0; a < 8; ++a) EXPECT_EQ(seen[a], 1);
}

TEST(VtkHexWriterTest, BadInputThrowsNamingThePath) {
  const HexLattice lattice = MakeBoxHexLattice(Vec3(1.0, 1.0, 1.0), 1, 1, 1);
  const std::vector<Vec3> too_few(3, Vec3::Zero());
  try {
    WriteVtkHexLattice("/tmp/x.vtk", lattice, &too_few);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("'/tmp/x.vtk': 3 positions given for 8 nodes"),
              std::string::npos)
        << error.what();
  }
  EXPECT_THROW(WriteVtkHexLattice("/nonexistent_dir/x.vtk", lattice), InputError);
  HexLattice broken = lattice;
  broken.hexes[0][5] = 99;
  EXPECT_THROW(WriteVtkHexLattice(::testing::TempDir() + "/broken.vtk", broken), InputError);
}

}  // namespace
}  // namespace taut
