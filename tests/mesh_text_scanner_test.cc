#include "plugin/mesh_text_scanner.h"

#include <gtest/gtest.h>

#include "plugin/box_tet_mesher.h"
#include "tests/mesh_file_test_util.h"

namespace taut::internal {
namespace {

using mesh_test::ExpectMeshFileError;

TEST(MeshTextScannerTest, CountsLinesAcrossBlankCommentAndCrLfLines) {
  const std::string text = "# header\r\n\r\n  1 2 # three\r\n\n\t4\n5";
  MeshTextScanner s(text, "a.node", '#');
  ASSERT_TRUE(s.NextLine());
  EXPECT_EQ(s.line_number(), 3);
  EXPECT_EQ(s.CountTokensLeft(), 2);
  EXPECT_EQ(s.PeekToken(), "1");
  EXPECT_EQ(s.ReadInt("a"), 1);
  EXPECT_EQ(s.ReadInt("b"), 2);
  EXPECT_TRUE(s.AtLineEnd());  // the comment and the '\r' are gone
  ASSERT_TRUE(s.NextLine());
  EXPECT_EQ(s.line_number(), 5);
  EXPECT_EQ(s.ReadInt("c"), 4);
  ASSERT_TRUE(s.NextLine());
  EXPECT_EQ(s.line_number(), 6);
  EXPECT_EQ(s.line(), "5");
  EXPECT_FALSE(s.NextLine());
  EXPECT_EQ(s.line_number(), 6);  // end-of-file errors point at the last line
}

TEST(MeshTextScannerTest, ParsesNumbersStrictly) {
  const std::string text = "+5 -3 1e-3 +.5 2.\n";
  MeshTextScanner s(text, "f");
  s.NextLine();
  EXPECT_EQ(s.ReadInt("i"), 5);
  EXPECT_EQ(s.ReadInt("i"), -3);
  EXPECT_EQ(s.ReadDouble("x"), 1e-3);
  EXPECT_EQ(s.ReadDouble("x"), 0.5);
  EXPECT_EQ(s.ReadDouble("x"), 2.0);
  struct Case {
    const char* token;
    bool integer;
    const char* reason;
  };
  const Case cases[] = {
      {"1.0", true, "expected node tag (an integer), got '1.0'"},
      {"12x", true, "expected node tag (an integer), got '12x'"},
      {"+-1", true, "expected node tag (an integer), got '+-1'"},
      {"99999999999999999999", true, "node tag '99999999999999999999' is too large"},
      {"abc", false, "expected x coordinate (a number), got 'abc'"},
      {"nan", false, "x coordinate 'nan' is not finite"},
      {"-inf", false, "x coordinate '-inf' is not finite"},
      {"1e999", false, "x coordinate '1e999' is out of the range of a double"},
      {"0x1p3", false, "expected x coordinate (a number), got '0x1p3'"},
  };
  for (const Case& c : cases) {
    const std::string line = std::string("\n\n") + c.token + "\n";
    MeshTextScanner t(line, "f.msh");
    t.NextLine();
    ExpectMeshFileError([&] { c.integer ? t.ReadInt("node tag") : t.ReadDouble("x coordinate"); },
                        "f.msh", 3, c.reason);
  }
}

TEST(MeshTextScannerTest, RangeChecksAndLineEnds) {
  const std::string text = "7 8\n9\n";
  MeshTextScanner s(text, "m.ele");
  s.NextLine();
  ExpectMeshFileError([&] { s.ReadIntInRange("node index", 1, 6); }, "m.ele", 1,
                      "node index 7 is out of range [1, 6]");
  ExpectMeshFileError([&] { s.ExpectLineEnd("the index"); }, "m.ele", 1,
                      "unexpected '8' after the index");
  s.ReadToken("x");
  ExpectMeshFileError([&] { s.ReadToken("y coordinate"); }, "m.ele", 1,
                      "expected y coordinate, found the end of the line");
  s.set_cross_lines(true);
  EXPECT_EQ(s.ReadInt("y"), 9);  // continues on line 2
  EXPECT_FALSE(s.HasMoreTokens());
  ExpectMeshFileError([&] { s.ReadToken("z coordinate"); }, "m.ele", 2,
                      "unexpected end of file while reading z coordinate");
  ExpectMeshFileError([&] { s.RequireLine("the header"); }, "m.ele", 2,
                      "unexpected end of file while reading the header");
}

TEST(MeshTextScannerTest, CapReserveIsBoundedByTheRestOfTheFile) {
  const std::string text = "header\n" + std::string(100, 'x');
  MeshTextScanner s(text, "f");
  s.NextLine();
  EXPECT_EQ(s.bytes_left(), 100u);
  EXPECT_EQ(s.CapReserve(5, 8), 5u);
  EXPECT_EQ(s.CapReserve(2000000000, 8), 13u);  // 100 / 8 + 1
  EXPECT_EQ(s.CapReserve(-4, 8), 0u);
}

TEST(MeshTextScannerTest, QuoteTokenEscapesAndTruncates) {
  EXPECT_EQ(QuoteToken("ab"), "'ab'");
  EXPECT_EQ(QuoteToken(std::string("a\0\xff\\", 4)), "'a\\x00\\xff\\x5c'");
  EXPECT_EQ(QuoteToken(std::string(40, 'z')), "'" + std::string(32, 'z') + "...'");
}

TEST(MeshTextScannerTest, MissingFileNamesThePath) {
  const std::string path = mesh_test::TempPath("does_not_exist.msh");
  ExpectMeshFileError([&] { ReadMeshFileText(path); }, path, 0, "cannot open");
}

TEST(OrientAndValidateTetMeshTest, FlipsInvertedTetsAndRejectsDegenerateOnes) {
  TetMesh mesh = MakeBoxTetMesh(Vec3(1, 2, 3), 2, 1, 1);
  const TetMesh original = mesh;
  for (std::size_t e = 0; e < mesh.tets.size(); e += 2) std::swap(mesh.tets[e][2], mesh.tets[e][3]);
  EXPECT_EQ(OrientAndValidateTetMesh(mesh), 6);  // 12 tets, every second one inverted
  for (const auto& t : mesh.tets) {
    const auto& X = mesh.nodes;
    EXPECT_GT(CalcTetSignedVolume(X[t[0]], X[t[1]], X[t[2]], X[t[3]]), 0.0);
  }
  for (std::size_t e = 1; e < mesh.tets.size(); e += 2) EXPECT_EQ(mesh.tets[e], original.tets[e]);

  mesh.nodes.push_back(Vec3(0.25, 0, 0));  // node 12, on the edge from node 0 to node 1
  mesh.tets.push_back({0, 1, 12, 3});
  mesh.source = "flat.vtk";
  try {
    OrientAndValidateTetMesh(mesh);
    ADD_FAILURE() << "degenerate tet accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("flat.vtk: element 12 is degenerate"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace taut::internal
