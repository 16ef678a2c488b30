#include "plugin/vtk_reader.h"

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

// Header and POINTS (three points per line, as VTK writes them) with a FIELD block before and a
// METADATA block after, as ParaView 5.x writes them.
std::string HeaderAndPoints(const TetMesh& mesh) {
  std::string text =
      "# vtk DataFile Version 5.1\n\nASCII\nDATASET UNSTRUCTURED_GRID\n"
      "FIELD FieldData 1\nTIME 1 1 double\n0.5\nPOINTS " +
      std::to_string(mesh.nodes.size()) + " double\n";
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i)
    for (int k = 0; k < 3; ++k)
      text += Real(mesh.nodes[i][k]) + (k == 2 && i % 3 == 2 ? "\n" : " ");
  return text +
         "\nMETADATA\nINFORMATION 1\nNAME L2_NORM_RANGE LOCATION vtkDataArray\nDATA 2 0 3\n\n";
}

// Cell list: a vertex, then each tet (VTK order, nodes 0 and 1 swapped unless `ours`) followed by
// one of its faces as a triangle.
std::vector<std::vector<int>> MixedCells(const TetMesh& mesh, bool ours_every_second = false) {
  std::vector<std::vector<int>> cells = {{0}};
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) {
    const auto& t = mesh.tets[e];
    const bool ours = ours_every_second && e % 2 == 0;
    cells.push_back({ours ? t[0] : t[1], ours ? t[1] : t[0], t[2], t[3]});
    cells.push_back({t[0], t[1], t[2]});
  }
  return cells;
}

// VTK cell type for a cell of the given size.
int VtkType(std::size_t size) { return size == 4 ? 10 : size == 3 ? 5 : 1; }

// A classic legacy file (CELLS "<npts> <ids>") with point and cell data after the grid.
std::string ClassicText(const TetMesh& mesh, const std::vector<std::vector<int>>& cells) {
  std::string text = HeaderAndPoints(mesh);
  std::size_t size = 0;
  for (const auto& c : cells) size += 1 + c.size();
  text += "CELLS " + std::to_string(cells.size()) + " " + std::to_string(size) + "\n";
  for (const auto& c : cells) {
    text += std::to_string(c.size());
    for (int a : c) text += " " + std::to_string(a);
    text += "\n";
  }
  text += "CELL_TYPES " + std::to_string(cells.size()) + "\n";
  for (std::size_t i = 0; i < cells.size(); ++i)
    text += std::to_string(VtkType(cells[i].size())) + (i % 5 == 4 ? "\n" : " ");
  return text + "\nPOINT_DATA " + std::to_string(mesh.nodes.size()) +
         "\nSCALARS t float 1\nLOOKUP_TABLE default\n1 2 3\n";
}

// Writes text to a temp file named name; returns its path.
std::string WriteVtk(const std::string& text, const std::string& name = "beam.vtk") {
  const std::string path = TempPath(name);
  WriteTextFile(path, text);
  return path;
}

TEST(VtkReaderTest, RoundTripsClassicCellsSkippingOtherCellTypes) {
  const TetMesh mesh = MakeTestMesh();
  const std::string path = WriteVtk(ClassicText(mesh, MixedCells(mesh)));
  const TetMesh read = ReadVtkMesh(path);
  mesh_test::ExpectSameMesh(mesh, read);
  EXPECT_EQ(read.source, path);
}

TEST(VtkReaderTest, RoundTripsVersion51OffsetsAndConnectivity) {
  const TetMesh mesh = MakeTestMesh();
  const auto cells = MixedCells(mesh);
  std::string text = HeaderAndPoints(mesh);
  std::string offsets = "0", connectivity;
  std::size_t size = 0;
  for (const auto& c : cells) {
    size += c.size();
    offsets += " " + std::to_string(size);
    for (int a : c) connectivity += std::to_string(a) + (size % 7 == 0 ? "\n" : " ");
  }
  text += "CELLS " + std::to_string(cells.size() + 1) + " " + std::to_string(size) +
          "\nOFFSETS vtktypeint64\n" + offsets + "\nCONNECTIVITY vtktypeint64\n" + connectivity +
          "\nCELL_TYPES " + std::to_string(cells.size()) + "\n";
  for (const auto& c : cells) text += std::to_string(VtkType(c.size())) + "\n";
  mesh_test::ExpectSameMesh(mesh, ReadVtkMesh(WriteVtk(text)));
}

TEST(VtkReaderTest, ReorientsTetsGivenInEitherOrientation) {
  const TetMesh mesh = MakeTestMesh();
  mesh_test::ExpectSameMesh(mesh, ReadVtkMesh(WriteVtk(ClassicText(mesh, MixedCells(mesh, true)))));
}

// A four-point file around the given CELLS and CELL_TYPES text (POINTS on lines 5-6).
std::string Small(const std::string& cells_and_types) {
  return "# vtk DataFile Version 3.0\ntitle\nASCII\nDATASET UNSTRUCTURED_GRID\n"
         "POINTS 5 float\n0 0 0 1 0 0 0 1 0\n0 0 1 1 1 0\n" +
         cells_and_types;
}

TEST(VtkReaderTest, ReadsTheSampleFile) {
  mesh_test::ExpectUnitCube(ReadVtkMesh(std::string(TAUT_TEST_DATA_DIR) + "/unit_cube_v51.vtk"));
}

TEST(VtkReaderTest, RejectsDegenerateTetNamingItsIndex) {
  // Point 4 lies in the z = 0 plane of points 0, 1 and 2.
  const std::string path =
      WriteVtk(Small("CELLS 3 15\n4 0 1 2 3\n4 1 3 2 0\n4 0 1 2 4\nCELL_TYPES 3\n10 10 10\n"));
  try {
    ReadVtkMesh(path);
    ADD_FAILURE() << "flat tet accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path + ": element 2 is degenerate"), std::string::npos)
        << e.what();
  }
}

TEST(VtkReaderTest, ReportsParseErrorsWithFileLineAndReason) {
  const std::string types = "CELL_TYPES 1\n10\n";
  struct Case {
    std::string text;
    int line;
    std::string reason;
  };
  const Case cases[] = {
      {"# vtk DataFile Version 3.0\nt\nBINARY\n", 3, "binary VTK files are not supported"},
      {"ply\nformat ascii 1.0\n", 1, "not a legacy VTK file"},
      {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\n", 4,
       "dataset type 'POLYDATA' is not supported"},
      {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 5 float\n0 0 0\n"
       "1 0 0\n",
       7, "unexpected end of file while reading point coordinate"},
      {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 2 float\n0 0 0\n"
       "1 0 0,5\n",
       7, "expected point coordinate (a number), got '0,5'"},
      {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 1 float\n0 nan 0\n",
       6, "point coordinate 'nan' is not finite"},
      {Small("CELLS 1 5\n4 0 1 2 9\n" + types), 9,
       "cell 0 refers to point 9 but POINTS has 5 points"},
      {Small("CELLS 2 10\n3 0 1 2\n\n4 0 1 2 3\n" + types), 8,
       "announces 10 integers but the cells up to line 11 hold 9"},
      {Small("CELLS 1 4\n3 0 1 2\nCELL_TYPES 1\n10\n"), 9,
       "cell 0 is a VTK_TETRA (type 10) with 3 points; expected 4"},
      {Small("CELLS 1 5\n4 0 1 2 3\nCELL_TYPES 2\n10 10\n"), 10,
       "CELL_TYPES has 2 entries but CELLS has 1 cells"},
      {Small("CELLS 2 8\n3 0 1 2\n3 1 2 3\nCELL_TYPES 2\n5 5\n"), 11,
       "no VTK_TETRA cells (type 10); found 2 of type 5"},
      {Small("CELLS 1 11\n10 0 1 2 3 0 1 2 3 0 1\nCELL_TYPES 1\n24\n"), 10,
       "found 1 of type 24 (quadratic tetra, not supported)"},
      {Small("CELLS 1 5\n4 0 1 2 3\n"), 9, "no CELL_TYPES section"},
      {Small("CELLS 1 5\n4 0 1 2 3\nPOLYGONS 1 4\n"), 10, "unexpected keyword 'POLYGONS'"},
      {Small("CELLS 3 5\nOFFSETS vtktypeint64\n0 4 3\n"), 10,
       "cell offset 3 is out of range [4, 5]"},
      {Small("CELLS 2 5\nOFFSETS vtktypeint64\n0 4\n"), 10,
       "last offset 4 differs from the connectivity size 5"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.reason);
    const std::string path = WriteVtk(c.text);
    ExpectMeshFileError([&] { ReadVtkMesh(path); }, path, c.line, c.reason);
  }
  const std::string missing = TempPath("missing.vtk");
  ExpectMeshFileError([&] { ReadVtkMesh(missing); }, missing, 0, "cannot open");
}

TEST(VtkReaderTest, SurvivesMutatedAndRandomInput) {
  const TetMesh mesh = MakeBoxTetMesh(Vec3(1, 1, 1), 2, 1, 1);
  const auto counts =
      mesh_test::RunFuzz(ClassicText(mesh, MixedCells(mesh)), 4000,
                         [](const std::string& text) { internal::ParseVtkMesh(text, "f.vtk"); });
  EXPECT_GT(counts.parsed, 0);
  EXPECT_GT(counts.rejected, 1000);
  std::printf("vtk fuzz: parsed %d, rejected %d\n", counts.parsed, counts.rejected);
}

}  // namespace
}  // namespace taut
