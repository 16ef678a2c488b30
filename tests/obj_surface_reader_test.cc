#include "plugin/obj_surface_reader.h"

#include <gtest/gtest.h>

#include <string>

#include "plugin/mesh_file_error.h"
#include "tests/mesh_file_test_util.h"

namespace taut {
namespace {

using mesh_test::Real;
using mesh_test::TempPath;
using mesh_test::WriteTextFile;

// Expects ReadObjSurface(path) to throw InputError starting with "path: " and containing reason.
void ExpectObjError(const std::string& path, const std::string& reason) {
  try {
    ReadObjSurface(path);
    ADD_FAILURE() << "no error; expected " << reason;
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind(path + ": ", 0), 0u) << what;
    EXPECT_NE(what.find(reason), std::string::npos) << what << "\n  expected: " << reason;
  }
}

TEST(ObjSurfaceReaderTest, RoundTripsAnIcosphereWithGroupsAndAttributes) {
  const SurfaceMesh sphere = MakeIcosphereSurface(1.7, 2, Vec3(-0.25, 1.0 / 3, 0.5));
  std::string text = "# test\nmtllib missing.mtl\no sphere\n";
  for (const Vec3& v : sphere.vertices)
    text += "v " + Real(v.x()) + " " + Real(v.y()) + " " + Real(v.z()) + "\n";
  text += "vn 0 0 1\nvt 0.5 0.5\n";
  for (std::size_t t = 0; t < sphere.triangles.size(); ++t) {
    if (t == sphere.triangles.size() / 2) text += "g second_half\nusemtl none\n";
    const Triangle& f = sphere.triangles[t];
    // Mix "i", "i/t/n" and "i//n" forms.
    const char* suffix = t % 3 == 0 ? "" : (t % 3 == 1 ? "/1/1" : "//1");
    text += "f";
    for (int i : f) text += " " + std::to_string(i + 1) + suffix;
    text += "\n";
  }
  const std::string path = TempPath("sphere.obj");
  WriteTextFile(path, text);
  const SurfaceMesh read = ReadObjSurface(path);
  EXPECT_EQ(read.source, path);
  ASSERT_EQ(read.vertices.size(), sphere.vertices.size());
  ASSERT_EQ(read.triangles.size(), sphere.triangles.size());
  double max_error = 0.0;
  for (std::size_t i = 0; i < sphere.vertices.size(); ++i)
    max_error = std::max(max_error, (read.vertices[i] - sphere.vertices[i]).cwiseAbs().maxCoeff());
  EXPECT_LE(max_error, 1e-15);  // tinyobjloader's own double parser: within an ulp or so
  for (std::size_t t = 0; t < sphere.triangles.size(); ++t)
    EXPECT_EQ(read.triangles[t], sphere.triangles[t]) << t;
  EXPECT_NO_THROW(ValidateClosedSurface(read));
}

TEST(ObjSurfaceReaderTest, TriangulatesQuadsAndResolvesNegativeIndices) {
  const std::string path = TempPath("cube.obj");
  std::string text;
  for (int n = 0; n < 8; ++n)
    text += "v " + std::to_string(n & 1) + " " + std::to_string(n >> 1 & 1) + " " +
            std::to_string(n >> 2) + "\n";
  // Outward quads of the unit cube; the last one with negative (relative) indices.
  text += "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf -7 -5 -1 -3\n";
  WriteTextFile(path, text);
  const SurfaceMesh cube = ReadObjSurface(path);
  EXPECT_EQ(cube.vertices.size(), 8u);
  EXPECT_EQ(cube.triangles.size(), 12u);
  EXPECT_NO_THROW(ValidateClosedSurface(cube));
  EXPECT_NEAR(CalcSurfaceSignedVolume(cube), 1.0, 1e-15);
}

TEST(ObjSurfaceReaderTest, BadFilesAreReportedNamingTheFile) {
  const std::string missing = TempPath("missing.obj");
  ExpectObjError(missing, "cannot open");
  const std::string no_faces = TempPath("no_faces.obj");
  WriteTextFile(no_faces, "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\n");
  ExpectObjError(no_faces, "no triangles");
  const std::string out_of_range = TempPath("range.obj");
  WriteTextFile(out_of_range, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
  ExpectObjError(out_of_range, "face 0 of shape '' refers to vertex 8 but the file has 3 vertices");
  const std::string zero_index = TempPath("zero.obj");
  WriteTextFile(zero_index, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n");
  ExpectObjError(zero_index, "cannot parse OBJ: ");
  const std::string overflow = TempPath("overflow.obj");
  WriteTextFile(overflow, "v 1e999 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  ExpectObjError(overflow, "vertex 0 has a non-finite coordinate");
}

}  // namespace
}  // namespace taut
