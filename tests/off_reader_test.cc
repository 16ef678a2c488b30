#include "plugin/off_reader.h"

#include <gtest/gtest.h>

#include <string>

#include "plugin/mesh_file_error.h"
#include "tests/mesh_file_test_util.h"

namespace taut {
namespace {

using mesh_test::ExpectMeshFileError;
using mesh_test::Real;
using mesh_test::TempPath;
using mesh_test::WriteTextFile;

// OFF text of mesh with comments, blank lines and a colour after some vertices.
std::string OffText(const SurfaceMesh& mesh) {
  std::string text = "OFF  # header\n\n# counts\n" + std::to_string(mesh.vertices.size()) + " " +
                     std::to_string(mesh.triangles.size()) + " 0\n";
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Vec3& v = mesh.vertices[i];
    text += Real(v.x()) + " " + Real(v.y()) + "\t" + Real(v.z()) +
            (i % 3 == 0 ? " 0.5 0.5 0.5 1\n" : "\r\n");
  }
  for (const Triangle& t : mesh.triangles)
    text += "3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) +
            "\n";
  return text;
}

// Parses text as a file named "s.off".
SurfaceMesh Parse(const std::string& text) { return internal::ParseOffSurface(text, "s.off"); }

TEST(OffReaderTest, RoundTripsAnIcosphereBitForBit) {
  const SurfaceMesh sphere = MakeIcosphereSurface(0.37, 3, Vec3(0.1, -2.0 / 3, 1e-3));
  const std::string path = TempPath("sphere.off");
  WriteTextFile(path, OffText(sphere));
  const SurfaceMesh read = ReadOffSurface(path);
  EXPECT_EQ(read.source, path);
  ASSERT_EQ(read.vertices.size(), sphere.vertices.size());
  ASSERT_EQ(read.triangles.size(), sphere.triangles.size());
  for (std::size_t i = 0; i < sphere.vertices.size(); ++i)
    EXPECT_EQ(read.vertices[i], sphere.vertices[i]) << i;
  for (std::size_t t = 0; t < sphere.triangles.size(); ++t)
    EXPECT_EQ(read.triangles[t], sphere.triangles[t]) << t;
  EXPECT_NO_THROW(ValidateClosedSurface(read));
}

TEST(OffReaderTest, FanTriangulatesQuadsOfAUnitCubeKeepingTheWinding) {
  // Counts on the header line, COFF header, face colours after the indices.
  const std::string text =
      "COFF 8 6 12\n"
      "0 0 0\n1 0 0\n0 1 0\n1 1 0\n0 0 1\n1 0 1\n0 1 1\n1 1 1\n"
      "4 0 2 3 1  255 0 0\n4 4 5 7 6\n4 0 1 5 4\n4 2 6 7 3\n4 0 4 6 2\n4 1 3 7 5\n";
  const SurfaceMesh cube = Parse(text);
  ASSERT_EQ(cube.triangles.size(), 12u);
  EXPECT_EQ(cube.triangles[0], (Triangle{0, 2, 3}));
  EXPECT_EQ(cube.triangles[1], (Triangle{0, 3, 1}));
  EXPECT_NO_THROW(ValidateClosedSurface(cube));
  EXPECT_NEAR(CalcSurfaceSignedVolume(cube), 1.0, 1e-15);
  // A pentagon gives 3 triangles of a fan from its first vertex.
  const SurfaceMesh pentagon = Parse("OFF\n5 1\n0 0 0\n1 0 0\n1 1 0\n.5 2 0\n0 1 0\n5 0 1 2 3 4\n");
  ASSERT_EQ(pentagon.triangles.size(), 3u);
  EXPECT_EQ(pentagon.triangles[2], (Triangle{0, 3, 4}));
}

TEST(OffReaderTest, BadInputNamesFileLineAndReason) {
  const std::string head = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n";
  const auto expect = [](const std::string& text, int line, const std::string& reason) {
    ExpectMeshFileError([&] { Parse(text); }, "s.off", line, reason);
  };
  expect("PLY\n3 1\n", 1, "expected the header 'OFF', got 'PLY'");
  expect("4OFF\n3 1\n", 1, "expected the header 'OFF'");
  expect("OFF\n0 1\n", 2, "vertex count 0 is out of range");
  expect("OFF\n3 -1\n", 2, "face count -1 is out of range");
  expect("OFF\n3 1 0 7\n", 2, "unexpected '7' after the counts");
  expect("OFF\n3 1\n0 0 0\n1 0 x\n", 4, "expected vertex z (a number), got 'x'");
  expect("OFF\n3 1\n0 0 0\n1 0 nan\n", 4, "vertex z 'nan' is not finite");
  expect("OFF\n3 1\n0 0 0\n1 0\n", 4, "expected vertex z, found the end of the line");
  expect(head, 5, "unexpected end of file while reading a face");
  expect(head + "3 0 1 3\n", 6, "vertex index 3 is out of range [0, 2]");
  expect(head + "2 0 1\n", 6, "face vertex count 2 is out of range [3,");
  expect(head + "4 0 1 2\n", 6, "face 0 lists 4 vertices but only 3 values follow");
  expect(head + "3 0 1 0\n", 6, "face 0 repeats vertex 0");
  expect(head + "3 0 1 2\n3 0 1 2\n", 7, "unexpected data after the 1 faces");
  expect("OFF\n99999999999999999999 1\n", 2, "is too large");
}

TEST(OffReaderTest, EmptyAndMissingFilesAreReported) {
  try {
    Parse("# only a comment\n");
    ADD_FAILURE() << "no error";
  } catch (const MeshFileError& e) {
    EXPECT_NE(std::string(e.what()).find("unexpected end of file while reading the OFF header"),
              std::string::npos)
        << e.what();
  }
  const std::string missing = TempPath("missing.off");
  ExpectMeshFileError([&] { ReadOffSurface(missing); }, missing, 0, "cannot open");
}

TEST(OffReaderTest, ArbitraryBytesParseOrThrowInputError) {
  const std::string seed = OffText(MakeIcosphereSurface(1.0, 0));
  const mesh_test::FuzzCounts counts = mesh_test::RunFuzz(seed, 4000, [](const std::string& t) {
    const SurfaceMesh mesh = Parse(t);
    // Whatever parses holds valid indices.
    for (const Triangle& tri : mesh.triangles)
      for (int i : tri) ASSERT_TRUE(i >= 0 && i < static_cast<int>(mesh.vertices.size()));
  });
  EXPECT_GT(counts.parsed, 0);
  EXPECT_GT(counts.rejected, 0);
  // A huge vertex count with little data reserves little and fails at the end of the file.
  ExpectMeshFileError([] { Parse("OFF\n2000000000 2000000000\n0 0 0\n"); }, "s.off", 3,
                      "unexpected end of file while reading a vertex");
}

}  // namespace
}  // namespace taut
