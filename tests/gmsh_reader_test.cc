#include "plugin/gmsh_reader.h"

#include <gtest/gtest.h>

#include <cstdio>

#include "plugin/box_tet_mesher.h"
#include "plugin/mesh_file_error.h"
#include "tests/mesh_file_test_util.h"

namespace taut {
namespace {

using mesh_test::ExpectMeshFileError;
using mesh_test::Real;
using mesh_test::TempPath;
using mesh_test::WriteTextFile;

// A box mesh with irregular coordinates, so a lost digit shows.
TetMesh MakeTestMesh() {
  return MakeBoxTetMesh(Vec3(1.3, 0.7, 0.5), 3, 2, 2, Vec3(-0.1, 0.2, 1.0 / 3));
}

// Non-contiguous, decreasing node tags.
long long NodeTag(std::size_t i) { return 5000 - 7 * static_cast<long long>(i); }

// "x y z" of node i.
std::string Coordinates(const TetMesh& mesh, std::size_t i) {
  return Real(mesh.nodes[i].x()) + " " + Real(mesh.nodes[i].y()) + " " + Real(mesh.nodes[i].z());
}

// Node tags of tet e in Gmsh's orientation (nodes 0 and 1 swapped) unless `ours`.
std::string TetTags(const TetMesh& mesh, std::size_t e, bool ours = false) {
  const auto& t = mesh.tets[e];
  const int order[4] = {ours ? t[0] : t[1], ours ? t[1] : t[0], t[2], t[3]};
  std::string text;
  for (int a : order) text += " " + std::to_string(NodeTag(a));
  return text;
}

// A version 2.2 file: a point, two lines, the boundary triangles and the tets, mixed.
std::string Gmsh22Text(const TetMesh& mesh) {
  std::string text =
      "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n3 1 \"body\"\n"
      "$EndPhysicalNames\n$Nodes\n" +
      std::to_string(mesh.nodes.size()) + "\n";
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i)
    text += std::to_string(NodeTag(i)) + " " + Coordinates(mesh, i) + "\n";
  const auto faces = CalcBoundaryFaces(mesh);
  text += "$EndNodes\n$Elements\n" + std::to_string(3 + faces.size() + mesh.tets.size()) + "\n";
  long long tag = 1;
  text += std::to_string(tag++) + " 15 2 0 1 " + std::to_string(NodeTag(0)) + "\n";
  for (int k = 0; k < 2; ++k)
    text += std::to_string(tag++) + " 1 2 0 1 " + std::to_string(NodeTag(k)) + " " +
            std::to_string(NodeTag(k + 1)) + "\n";
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) {
    if (e < faces.size())
      text += std::to_string(tag++) + " 2 3 0 2 -1 " + std::to_string(NodeTag(faces[e][0])) + " " +
              std::to_string(NodeTag(faces[e][1])) + " " + std::to_string(NodeTag(faces[e][2])) +
              "\n";
    text += std::to_string(tag++) + " 4 2 1 1" + TetTags(mesh, e) + "\n";
  }
  for (std::size_t f = mesh.tets.size(); f < faces.size(); ++f)
    text += std::to_string(tag++) + " 2 2 0 2 " + std::to_string(NodeTag(faces[f][0])) + " " +
            std::to_string(NodeTag(faces[f][1])) + " " + std::to_string(NodeTag(faces[f][2])) +
            "\n";
  return text + "$EndElements\n";
}

// A version 4.1 file: $Entities, nodes in a point block and a volume block (tags before
// coordinates), then a point block, a triangle block and the tets in two blocks.
std::string Gmsh41Text(const TetMesh& mesh) {
  const std::size_t n = mesh.nodes.size(), m = mesh.tets.size(), half = m / 2;
  const auto faces = CalcBoundaryFaces(mesh);
  std::string text =
      "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n1 0 0 1\n1 0 0 0 0\n"
      "1 0 0 0 1 1 1 0 0\n$EndEntities\n$Nodes\n";
  text += "2 " + std::to_string(n) + " " + std::to_string(NodeTag(n - 1)) + " " +
          std::to_string(NodeTag(0)) + "\n";
  text += "0 1 0 1\n" + std::to_string(NodeTag(0)) + "\n" + Coordinates(mesh, 0) + "\n";
  text += "3 1 1 " + std::to_string(n - 1) + "\n";  // parametric: u v w follow x y z
  for (std::size_t i = 1; i < n; ++i) text += std::to_string(NodeTag(i)) + "\n";
  for (std::size_t i = 1; i < n; ++i) text += Coordinates(mesh, i) + " 0.5 0.25 0\n";
  text += "$EndNodes\n$Elements\n4 " + std::to_string(1 + faces.size() + m) + " 1 " +
          std::to_string(1 + faces.size() + m) + "\n";
  long long tag = 1;
  text += "0 1 15 1\n" + std::to_string(tag++) + " " + std::to_string(NodeTag(0)) + "\n";
  text += "3 1 4 " + std::to_string(half) + "\n";
  for (std::size_t e = 0; e < half; ++e) text += std::to_string(tag++) + TetTags(mesh, e) + "\n";
  text += "2 1 2 " + std::to_string(faces.size()) + "\n";
  for (const auto& f : faces)
    text += std::to_string(tag++) + " " + std::to_string(NodeTag(f[0])) + " " +
            std::to_string(NodeTag(f[1])) + " " + std::to_string(NodeTag(f[2])) + "\n";
  text += "3 1 4 " + std::to_string(m - half) + "\n";
  for (std::size_t e = half; e < m; ++e) text += std::to_string(tag++) + TetTags(mesh, e) + "\n";
  return text + "$EndElements\n$NodeData\n1\n\"u\"\n$EndNodeData\n";
}

// Writes text to a temp file named name; returns its path.
std::string WriteMsh(const std::string& text, const std::string& name = "beam.msh") {
  const std::string path = TempPath(name);
  WriteTextFile(path, text);
  return path;
}

TEST(GmshReaderTest, RoundTripsVersion22WithMixedElements) {
  const TetMesh mesh = MakeTestMesh();
  const std::string path = WriteMsh(Gmsh22Text(mesh));
  const TetMesh read = ReadGmshMesh(path);
  mesh_test::ExpectSameMesh(mesh, read);
  EXPECT_EQ(read.source, path);
}

TEST(GmshReaderTest, RoundTripsVersion41WithBlocksAndNonContiguousTags) {
  const TetMesh mesh = MakeTestMesh();
  mesh_test::ExpectSameMesh(mesh, ReadGmshMesh(WriteMsh(Gmsh41Text(mesh))));
}

TEST(GmshReaderTest, ReorientsTetsGivenInEitherOrientation) {
  const TetMesh mesh = MakeTestMesh();
  std::string text = Gmsh22Text(mesh);
  // Every second tet in taut's orientation (docs/math.md §0.1), not Gmsh's: both read the same.
  for (std::size_t e = 0; e < mesh.tets.size(); e += 2) {
    const std::string gmsh = TetTags(mesh, e) + "\n", ours = TetTags(mesh, e, true) + "\n";
    text.replace(text.find(gmsh), gmsh.size(), ours);
  }
  mesh_test::ExpectSameMesh(mesh, ReadGmshMesh(WriteMsh(text)));
}

TEST(GmshReaderTest, KeepsATetListedTwiceOnce) {
  const std::string text =
      "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n"
      "$EndNodes\n$Elements\n2\n1 4 2 1 1 1 2 3 4\n2 4 2 2 1 2 1 3 4\n$EndElements\n";
  const TetMesh read = ReadGmshMesh(WriteMsh(text));
  ASSERT_EQ(read.tets.size(), 1u);
  EXPECT_EQ(read.tets[0], (std::array<int, 4>{1, 0, 2, 3}));  // Gmsh order swapped to ours
}

// Minimal version 2.2 text around the given node and element lines.
std::string Msh22(const std::string& nodes, const std::string& elements) {
  return "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n" + nodes + "$EndNodes\n$Elements\n" +
         elements + "$EndElements\n";
}
const char kFiveNodes[] = "5\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n7 1 1 0\n";

TEST(GmshReaderTest, ReadsTheSampleFiles) {
  for (const char* name : {"/unit_cube_gmsh41.msh", "/unit_cube_gmsh22.msh"}) {
    SCOPED_TRACE(name);
    mesh_test::ExpectUnitCube(ReadGmshMesh(std::string(TAUT_TEST_DATA_DIR) + name));
  }
}

TEST(GmshReaderTest, RejectsDegenerateTetNamingItsIndex) {
  // Node 7 lies in the z = 0 plane of nodes 1, 2 and 3.
  const std::string path = WriteMsh(Msh22(kFiveNodes, "2\n1 4 0 1 2 3 4\n2 4 0 1 2 3 7\n"));
  try {
    ReadGmshMesh(path);
    ADD_FAILURE() << "flat tet accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path + ": element 1 is degenerate"), std::string::npos)
        << e.what();
  }
}

TEST(GmshReaderTest, ReportsParseErrorsWithFileLineAndReason) {
  const std::string tet = "1\n1 4 2 0 1 1 2 3 4\n";
  const std::string v41 = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
  struct Case {
    std::string text;
    int line;
    std::string reason;
  };
  const Case cases[] = {
      {Msh22(kFiveNodes, "1\n1 4 2 0 1 1 2 3\n"), 14,
       "expected 4 node tags for a tetrahedron, got 3"},
      {v41 + "$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n"
             "$Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3\n$EndElements\n",
       19, "expected 4 node tags for a tetrahedron, got 3"},
      {"$MeshFormat\n4.0 0 8\n$EndMeshFormat\n", 2, "unsupported .msh version '4.0'"},
      {"$MeshFormat\n3 0 8\n$EndMeshFormat\n", 2, "unsupported .msh version '3'"},
      {"$MeshFormat\n4.1 1 8\n\x01\x00\x00\x00\n$EndMeshFormat\n", 2, "binary .msh not supported"},
      {"solid cube\n", 1, "expected $MeshFormat on the first line"},
      {Msh22(kFiveNodes, "2\n1 2 0 1 2 3\n2 2 0 2 3 4\n"), 12,
       "no 4-node tetrahedra (element type 4) in $Elements; found 2 of type 2 (3-node triangle)"},
      {Msh22(kFiveNodes, "1\n1 11 0 1 2 3 4 1 2 3 4 1 2\n"), 12,
       "found 1 of type 11 (10-node tetrahedron, not supported)"},
      {"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n5\n1 0 0 0\n2 1 0 0\n", 7,
       "unexpected end of file after 2 of the 5 nodes announced on line 5"},
      {Msh22("3\n1 0 0 0\n2 1 0 0\n$EndNodes\n", tet), 8,
       "found '$EndNodes' after only 2 of the 3 nodes announced on line 5"},
      {Msh22("1\n1 0 0 0\n2 1 0 0\n", tet), 7,
       "expected $EndNodes after the 1 nodes announced on line 5, got '2'"},
      {Msh22("2\n1 0 0 0\n2 1 0 1.0.0\n", tet), 7, "expected z coordinate (a number), got '1.0.0'"},
      {Msh22("2\n1 0 0 0\n2 1 inf 1\n", tet), 7, "y coordinate 'inf' is not finite"},
      {Msh22("2\n1 0 0 0\n1 1 0 1\n", tet), 7, "node tag 1 is defined twice"},
      {Msh22(kFiveNodes, "1\n1 4 2 0 1 1 2 3 99\n"), 14, "node tag 99 is not defined in $Nodes"},
      {Msh22(kFiveNodes, "1\n1 4 9 0 1 1 2 3 4\n"), 14,
       "element declares 9 tags but its line holds only 6 more values"},
      {v41 + "$Nodes\n1 5 1 5\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n", 5,
       "announces 5 nodes but the node blocks up to line 14 hold 4"},
      {v41 + "$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n9\n", 9, "node tag 9 is out of range [1, 4]"},
      {v41 + "$Nodes\n2 1 1 1\n3 1 0 1\n1\n0 0 0\n3 1 0 1\n", 9,
       "node blocks hold more nodes than the 1 announced on line 5"},
      {v41 + "$Comments\nhello\n", 5, "section '$Comments' opened on line 4 has no '$EndComments'"},
      {v41 + "$Elements\n", 4, "$Elements comes before $Nodes"},
      {v41, 3, "end of file reached without an $Elements section"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.reason);
    const std::string path = WriteMsh(c.text);
    ExpectMeshFileError([&] { ReadGmshMesh(path); }, path, c.line, c.reason);
  }
  const std::string missing = TempPath("missing.msh");
  ExpectMeshFileError([&] { ReadGmshMesh(missing); }, missing, 0, "cannot open");
}

TEST(GmshReaderTest, SurvivesMutatedAndRandomInput) {
  const TetMesh mesh = MakeBoxTetMesh(Vec3(1, 1, 1), 2, 1, 1);
  const auto parse = [](const std::string& text) { internal::ParseGmshMesh(text, "f.msh"); };
  const auto v2 = mesh_test::RunFuzz(Gmsh22Text(mesh), 2000, parse);
  const auto v4 = mesh_test::RunFuzz(Gmsh41Text(mesh), 2000, parse);
  EXPECT_GT(v2.parsed + v4.parsed, 0);
  EXPECT_GT(v2.rejected + v4.rejected, 2000);
  std::printf("gmsh fuzz: parsed %d + %d, rejected %d + %d\n", v2.parsed, v4.parsed, v2.rejected,
              v4.rejected);
}

}  // namespace
}  // namespace taut
