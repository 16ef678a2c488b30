#include "plugin/vtk_writer.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "plugin/box_tet_mesher.h"
#include "plugin/mesh_file_error.h"
#include "plugin/vtk_reader.h"
#include "tests/mesh_file_test_util.h"

namespace taut {
namespace {

using mesh_test::TempPath;

// A box mesh whose coordinates need all 17 significant digits (thirds, tiny offsets).
TetMesh MakeTestMesh() {
  TetMesh mesh = MakeBoxTetMesh(Vec3(1.3, 0.7, 0.5), 3, 2, 2, Vec3(-0.1, 0.2, 1.0 / 3));
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i)
    mesh.nodes[i] += Vec3(1e-17 * i, 1.0 / (3 + i) * 1e-3, -2e-9 / 7);
  mesh.nodes[0].x() = -0.1 - 1e-3 / 3;
  return mesh;
}

// The whitespace-separated tokens of a file.
std::vector<std::string> ReadTokens(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> tokens;
  for (std::string token; in >> token;) tokens.push_back(token);
  return tokens;
}

// Index of the first token equal to word, or -1.
long Find(const std::vector<std::string>& tokens, const std::string& word, std::size_t from = 0) {
  for (std::size_t i = from; i < tokens.size(); ++i)
    if (tokens[i] == word) return static_cast<long>(i);
  return -1;
}

// Expects InputError whose message contains every part.
template <typename Write>
void ExpectInputError(Write&& write, const std::vector<std::string>& parts) {
  try {
    write();
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    for (const auto& part : parts)
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what() << " / " << part;
  }
}

TEST(VtkWriterTest, RestMeshReadsBackBitForBit) {
  const TetMesh mesh = MakeTestMesh();
  bool needs_17_digits = false;  // so the test would fail with fewer digits
  for (const Vec3& X : mesh.nodes)
    for (int k = 0; k < 3; ++k) {
      char text[32];
      std::snprintf(text, sizeof(text), "%.15g", X[k]);
      needs_17_digits = needs_17_digits || std::strtod(text, nullptr) != X[k];
    }
  EXPECT_TRUE(needs_17_digits);
  const std::string path = TempPath("rest.vtk");
  WriteVtkMesh(path, mesh);
  mesh_test::ExpectSameMesh(mesh, ReadVtkMesh(path));
}

TEST(VtkWriterTest, WritesDeformedPositionsAndTetsInVtkOrientation) {
  const TetMesh mesh = MakeTestMesh();
  std::vector<Vec3> x = mesh.nodes;
  for (Vec3& p : x) p = Vec3(p.x() * 1.1, p.y() - 0.3 * p.x(), p.z() + 1e-3 / 3);  // det > 0
  const std::string path = TempPath("deformed.vtk");
  WriteVtkMesh(path, mesh, &x);
  TetMesh read = ReadVtkMesh(path);
  EXPECT_EQ(read.tets, mesh.tets);
  for (std::size_t i = 0; i < x.size(); ++i) EXPECT_EQ(read.nodes[i], x[i]) << i;
  // In the file the first tet is (t1, t0, t2, t3), positive in VTK's det[X2-X1, X3-X1, X4-X1].
  const auto tokens = ReadTokens(path);
  const long cells = Find(tokens, "CELLS");
  ASSERT_GE(cells, 0);
  const auto& t = mesh.tets[0];
  EXPECT_EQ(tokens[cells + 3], "4");
  EXPECT_EQ(tokens[cells + 4], std::to_string(t[1]));
  EXPECT_EQ(tokens[cells + 5], std::to_string(t[0]));
  const Vec3 &a = x[t[1]], &b = x[t[0]], &c = x[t[2]], &d = x[t[3]];
  EXPECT_GT((b - a).dot((c - a).cross(d - a)), 0.0);
}

TEST(VtkWriterTest, WritesNamedPointAndCellFieldsExactly) {
  const TetMesh mesh = MakeTestMesh();
  VtkFields fields;
  std::vector<double> temperature, strain;
  std::vector<Vec3> velocity;
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i) {
    temperature.push_back(1.0 / (i + 3));
    velocity.push_back(Vec3(i, -1.0 / 7, 1e-300));
  }
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) strain.push_back(e * 0.1);
  fields.point_scalars = {{"temperature", temperature}};
  fields.point_vectors = {{"velocity", velocity}};
  fields.cell_scalars = {{"strain", strain}};
  const std::string path = TempPath("fields.vtk");
  WriteVtkMesh(path, mesh, nullptr, fields);
  mesh_test::ExpectSameMesh(mesh, ReadVtkMesh(path));  // the reader stops at POINT_DATA

  const auto tokens = ReadTokens(path);
  const long point_data = Find(tokens, "POINT_DATA");
  ASSERT_GE(point_data, 0);
  EXPECT_EQ(tokens[point_data + 1], std::to_string(mesh.nodes.size()));
  const long scalars = Find(tokens, "temperature", point_data);
  ASSERT_GE(scalars, 0);
  for (std::size_t i = 0; i < temperature.size(); ++i)  // after "double 1 LOOKUP_TABLE default"
    EXPECT_EQ(std::strtod(tokens[scalars + 5 + i].c_str(), nullptr), temperature[i]) << i;
  const long vectors = Find(tokens, "velocity", point_data);
  ASSERT_GE(vectors, 0);
  EXPECT_EQ(tokens[vectors - 1], "VECTORS");
  for (std::size_t i = 0; i < velocity.size(); ++i)
    for (int k = 0; k < 3; ++k)
      EXPECT_EQ(std::strtod(tokens[vectors + 2 + 3 * i + k].c_str(), nullptr), velocity[i][k]);
  const long cell_data = Find(tokens, "CELL_DATA");
  ASSERT_GT(cell_data, vectors);
  const long cell_scalars = Find(tokens, "strain", cell_data);
  ASSERT_GE(cell_scalars, 0);
  for (std::size_t e = 0; e < strain.size(); ++e)
    EXPECT_EQ(std::strtod(tokens[cell_scalars + 5 + e].c_str(), nullptr), strain[e]);
}

TEST(VtkWriterTest, WritesSurfaceTrianglesKeepingTheirWinding) {
  const TetMesh mesh = MakeTestMesh();
  const auto faces = CalcBoundaryFaces(mesh);
  const std::string path = TempPath("surface.vtk");
  WriteVtkSurface(path, mesh.nodes, faces);
  const auto tokens = ReadTokens(path);
  const long cells = Find(tokens, "CELLS");
  ASSERT_GE(cells, 0);
  EXPECT_EQ(tokens[cells + 1], std::to_string(faces.size()));
  EXPECT_EQ(tokens[cells + 2], std::to_string(4 * faces.size()));
  for (std::size_t f = 0; f < faces.size(); ++f) {
    EXPECT_EQ(tokens[cells + 3 + 4 * f], "3");
    for (int a = 0; a < 3; ++a)
      EXPECT_EQ(tokens[cells + 4 + 4 * f + a], std::to_string(faces[f][a])) << f;
  }
  const long types = Find(tokens, "CELL_TYPES");
  ASSERT_EQ(types, static_cast<long>(cells + 3 + 4 * faces.size()));
  for (std::size_t f = 0; f < faces.size(); ++f) EXPECT_EQ(tokens[types + 2 + f], "5");
  // The tet reader sees the triangles and says so at the CELL_TYPES line.
  const int types_line = 7 + static_cast<int>(mesh.nodes.size() + faces.size());
  mesh_test::ExpectMeshFileError(
      [&] { ReadVtkMesh(path); }, path, types_line,
      "no VTK_TETRA cells (type 10); found " + std::to_string(faces.size()) + " of type 5");
}

TEST(VtkWriterTest, RejectsBadInputAndUnwritablePaths) {
  const TetMesh mesh = MakeBoxTetMesh(Vec3(1, 1, 1), 1, 1, 1);
  const std::string bad_dir = TempPath("no_such_dir") + "/out.vtk";
  ExpectInputError([&] { WriteVtkMesh(bad_dir, mesh); }, {bad_dir, "cannot open"});
  const std::string path = TempPath("bad.vtk");
  std::vector<Vec3> short_positions(3, Vec3::Zero());
  ExpectInputError([&] { WriteVtkMesh(path, mesh, &short_positions); },
                   {path, "3 positions given for the 8 nodes"});
  VtkFields fields;
  fields.cell_scalars = {{"stress", std::vector<double>(5, 0.0)}};
  ExpectInputError([&] { WriteVtkMesh(path, mesh, nullptr, fields); },
                   {path, "field 'stress' has 5 values but there are 6 cells"});
  fields.cell_scalars = {{"von mises", std::vector<double>(6, 0.0)}};
  ExpectInputError([&] { WriteVtkMesh(path, mesh, nullptr, fields); },
                   {"field name 'von mises' must be non-empty and contain no blanks"});
  ExpectInputError(
      [&] {
        WriteVtkSurface(path, mesh.nodes, {{0, 1, 8}});
      },
      {path, "cell refers to node 8 but there are 8 points"});
}

TEST(VtkWriterTest, KeepsTheTitleOnOneLine) {
  TetMesh mesh = MakeBoxTetMesh(Vec3(1, 1, 1), 1, 1, 1);
  mesh.source = "two\nlines";
  const std::string path = TempPath("title.vtk");
  WriteVtkMesh(path, mesh);
  std::ifstream in(path);
  std::string line1, line2, line3;
  std::getline(in, line1);
  std::getline(in, line2);
  std::getline(in, line3);
  EXPECT_EQ(line2, "taut tet mesh two lines");
  EXPECT_EQ(line3, "ASCII");
  EXPECT_EQ(ReadVtkMesh(path).tets, mesh.tets);
}

}  // namespace
}  // namespace taut
