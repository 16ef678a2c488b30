#include "plugin/vtk_reader.h"

#include <cctype>
#include <climits>
#include <map>
#include <vector>

#include "plugin/mesh_text_scanner.h"

namespace taut {
namespace internal {
namespace {

constexpr long long kVtkTetra = 10;
constexpr long long kVtkQuadraticTetra = 24;

// Cells as read from CELLS: cell c has points conn[offsets[c] .. offsets[c+1]).
struct VtkCells {
  std::vector<long long> offsets;  // (num_cells + 1) start of each cell in conn
  std::vector<long long> conn;     // (total points of all cells) point ids
  std::vector<int> lines;          // (num_cells) line where each cell's point ids begin
};

// Parse state shared by the section readers.
struct VtkReader {
  MeshTextScanner s;
  TetMesh mesh;
  VtkCells cells;
  std::vector<long long> types;                         // (num_cells) VTK cell type of each cell
  int points_line = 0, cells_line = 0, types_line = 0;  // 0 until the section is read
};

// True if a and b are equal ignoring ASCII case.
bool EqualsNoCase(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(a[i])) !=
        std::tolower(static_cast<unsigned char>(b[i])))
      return false;
  return true;
}

// Fails unless the next token is the data type of a numeric array.
void ReadDataType(MeshTextScanner& s) {
  static constexpr const char* kTypes[] = {"bit",
                                           "unsigned_char",
                                           "char",
                                           "unsigned_short",
                                           "short",
                                           "unsigned_int",
                                           "int",
                                           "unsigned_long",
                                           "long",
                                           "float",
                                           "double",
                                           "vtkIdType",
                                           "vtktypeint64",
                                           "vtktypeint32",
                                           "vtktypeuint64",
                                           "vtktypeuint32",
                                           "vtktypeint8",
                                           "vtktypeuint8",
                                           "vtktypeint16",
                                           "vtktypeuint16",
                                           "vtktypefloat32",
                                           "vtktypefloat64"};
  const std::string_view type = s.ReadToken("a data type");
  for (const char* known : kTypes)
    if (EqualsNoCase(type, known)) return;
  s.Fail("unknown data type ", QuoteToken(type));
}

// Reads the header: version line, title, ASCII, "DATASET UNSTRUCTURED_GRID".
void ReadVtkHeader(MeshTextScanner& s) {
  constexpr std::string_view kMagic = "# vtk DataFile";
  if (!s.NextRawLine() || !EqualsNoCase(s.line().substr(0, kMagic.size()), kMagic))
    s.Fail("not a legacy VTK file: the first line must start with '# vtk DataFile Version'");
  if (!s.NextRawLine()) s.Fail("unexpected end of file while reading the title line");
  s.RequireLine("the file type (ASCII or BINARY)");
  const std::string_view format = s.ReadToken("ASCII or BINARY");
  if (EqualsNoCase(format, "BINARY")) s.Fail("binary VTK files are not supported; save as ASCII");
  if (!EqualsNoCase(format, "ASCII")) s.Fail("expected ASCII or BINARY, got ", QuoteToken(format));
  s.ExpectLineEnd("ASCII");
  s.set_cross_lines(true);
  const std::string_view dataset = s.ReadToken("DATASET");
  if (!EqualsNoCase(dataset, "DATASET")) s.Fail("expected DATASET, got ", QuoteToken(dataset));
  const std::string_view type = s.ReadToken("the dataset type");
  if (!EqualsNoCase(type, "UNSTRUCTURED_GRID"))
    s.Fail("dataset type ", QuoteToken(type), " is not supported; expected UNSTRUCTURED_GRID");
}

// Reads "POINTS <n> <type>" and its 3n coordinates.
void ReadPoints(VtkReader& r) {
  MeshTextScanner& s = r.s;
  if (r.points_line) s.Fail("second POINTS section; the first is on line ", r.points_line);
  r.points_line = s.line_number();
  const long long n = s.ReadIntInRange("point count", 0, INT_MAX);
  ReadDataType(s);
  r.mesh.nodes.reserve(s.CapReserve(n, 6));
  for (long long i = 0; i < n; ++i) {
    Vec3 X;
    for (int k = 0; k < 3; ++k) X[k] = s.ReadDouble("point coordinate");
    r.mesh.nodes.push_back(X);
  }
}

// Reads the classic CELLS body: per cell "<npts> <ids...>", size integers in all.
void ReadClassicCells(VtkReader& r, long long num_cells, long long size) {
  MeshTextScanner& s = r.s;
  VtkCells& c = r.cells;
  long long used = 0;
  for (long long i = 0; i < num_cells; ++i) {
    const long long npts = s.ReadIntInRange("cell point count", 0, INT_MAX);
    c.lines.push_back(s.line_number());
    used += 1 + npts;
    if (used > size)
      s.Fail("cells hold more than the ", size, " integers announced by CELLS on line ",
             r.cells_line);
    for (long long k = 0; k < npts; ++k) c.conn.push_back(s.ReadInt("point id"));
    c.offsets.push_back(static_cast<long long>(c.conn.size()));
  }
  if (used != size)
    throw MeshFileError(s.name(), r.cells_line,
                        Concat("announces ", size,
                               " integers but the cells "
                               "up to line ",
                               s.line_number(), " hold ", used));
}

// Reads the version 5.1 CELLS body: "OFFSETS <type>" num_offsets values, then
// "CONNECTIVITY <type>" size values.
void ReadOffsetCells(VtkReader& r, long long num_offsets, long long size) {
  MeshTextScanner& s = r.s;
  VtkCells& c = r.cells;
  s.ReadToken("OFFSETS");
  ReadDataType(s);
  if (num_offsets < 1) s.Fail("CELLS with OFFSETS needs at least 1 offset, got ", num_offsets);
  c.offsets.clear();
  for (long long i = 0; i < num_offsets; ++i) {
    const long long lo = i == 0 ? 0 : c.offsets.back(), hi = i == 0 ? 0 : size;
    c.offsets.push_back(s.ReadIntInRange("cell offset", lo, hi));
  }
  if (c.offsets.back() != size)
    s.Fail("last offset ", c.offsets.back(), " differs from the connectivity size ", size);
  const std::string_view keyword = s.ReadToken("CONNECTIVITY");
  if (!EqualsNoCase(keyword, "CONNECTIVITY"))
    s.Fail("expected CONNECTIVITY, got ", QuoteToken(keyword));
  ReadDataType(s);
  std::size_t cell = 0;
  for (long long k = 0; k < size; ++k) {
    const long long id = s.ReadInt("point id");
    for (; cell + 1 < c.offsets.size() && c.offsets[cell] == k; ++cell)
      c.lines.push_back(s.line_number());
    c.conn.push_back(id);
  }
  for (; cell + 1 < c.offsets.size(); ++cell) c.lines.push_back(s.line_number());
}

// Reads "CELLS <a> <b>" in either layout.
void ReadCells(VtkReader& r) {
  MeshTextScanner& s = r.s;
  if (r.cells_line) s.Fail("second CELLS section; the first is on line ", r.cells_line);
  r.cells_line = s.line_number();
  const long long a = s.ReadIntInRange("cell count", 0, INT_MAX);
  const long long b = s.ReadIntInRange("cell list size", 0, INT_MAX);
  r.cells.offsets.assign(1, 0);
  r.cells.conn.reserve(s.CapReserve(b, 2));
  if (s.HasMoreTokens() && EqualsNoCase(s.PeekToken(), "OFFSETS")) {
    ReadOffsetCells(r, a, b);
  } else {
    r.cells.lines.reserve(s.CapReserve(a, 2));
    ReadClassicCells(r, a, b);
  }
}

// Reads "CELL_TYPES <n>" and n integers.
void ReadCellTypes(VtkReader& r) {
  MeshTextScanner& s = r.s;
  if (r.types_line) s.Fail("second CELL_TYPES section; the first is on line ", r.types_line);
  r.types_line = s.line_number();
  const long long n = s.ReadIntInRange("cell type count", 0, INT_MAX);
  r.types.reserve(s.CapReserve(n, 2));
  for (long long i = 0; i < n; ++i) r.types.push_back(s.ReadInt("cell type"));
}

// Skips a METADATA block, which ends at the first blank line.
void SkipMetadata(MeshTextScanner& s) {
  while (s.NextRawLine())
    if (s.AtLineEnd()) return;
}

// Skips "FIELD <name> <#arrays>" and its arrays "<name> <#components> <#tuples> <type> values".
void SkipField(MeshTextScanner& s) {
  s.ReadToken("the field name");
  const long long num_arrays = s.ReadIntInRange("field array count", 0, INT_MAX);
  for (long long a = 0; a < num_arrays; ++a) {
    s.ReadToken("the array name");
    const long long components = s.ReadIntInRange("component count", 0, INT_MAX);
    const long long tuples = s.ReadIntInRange("tuple count", 0, INT_MAX);
    ReadDataType(s);
    for (long long k = 0; k < components * tuples; ++k) s.ReadToken("a field value");
    if (s.HasMoreTokens() && EqualsNoCase(s.PeekToken(), "METADATA")) {
      s.ReadToken("METADATA");
      SkipMetadata(s);
    }
  }
}

// Checks the sections against each other and keeps the tetrahedra.
void CollectTets(VtkReader& r) {
  MeshTextScanner& s = r.s;
  if (!r.points_line) s.Fail("no POINTS section");
  if (!r.cells_line) s.Fail("no CELLS section");
  if (!r.types_line) s.Fail("no CELL_TYPES section");
  const VtkCells& c = r.cells;
  const std::size_t num_cells = c.offsets.size() - 1;
  const std::string& name = s.name();
  if (r.types.size() != num_cells)
    throw MeshFileError(
        name, r.types_line,
        Concat("CELL_TYPES has ", r.types.size(), " entries but CELLS has ", num_cells, " cells"));
  const long long n = static_cast<long long>(r.mesh.nodes.size());
  std::map<long long, long long> skipped;  // cell type -> count
  for (std::size_t i = 0; i < num_cells; ++i) {
    const long long begin = c.offsets[i], end = c.offsets[i + 1];
    for (long long k = begin; k < end; ++k)
      if (c.conn[k] < 0 || c.conn[k] >= n)
        throw MeshFileError(
            name, c.lines[i],
            Concat("cell ", i, " refers to point ", c.conn[k], " but POINTS has ", n, " points"));
    if (r.types[i] != kVtkTetra) {
      ++skipped[r.types[i]];
      continue;
    }
    if (end - begin != 4)
      throw MeshFileError(name, c.lines[i],
                          Concat("cell ", i, " is a VTK_TETRA (type 10) with ", end - begin,
                                 " points; expected 4"));
    r.mesh.tets.push_back({static_cast<int>(c.conn[begin]), static_cast<int>(c.conn[begin + 1]),
                           static_cast<int>(c.conn[begin + 2]),
                           static_cast<int>(c.conn[begin + 3])});
  }
  if (r.mesh.tets.empty()) {
    std::string found;
    for (const auto& [type, count] : skipped)
      found += Concat(found.empty() ? "" : ", ", count, " of type ", type,
                      type == kVtkQuadraticTetra ? " (quadratic tetra, not supported)" : "");
    throw MeshFileError(
        name, r.types_line,
        "no VTK_TETRA cells (type 10); found " + (found.empty() ? std::string("no cells") : found));
  }
}

}  // namespace

TetMesh ParseVtkMesh(std::string_view text, const std::string& name) {
  VtkReader r{MeshTextScanner(text, name), {}, {}, {}};
  MeshTextScanner& s = r.s;
  ReadVtkHeader(s);
  while (s.HasMoreTokens()) {
    const std::string_view keyword = s.ReadToken("a section keyword");
    if (EqualsNoCase(keyword, "POINTS")) {
      ReadPoints(r);
    } else if (EqualsNoCase(keyword, "CELLS")) {
      ReadCells(r);
    } else if (EqualsNoCase(keyword, "CELL_TYPES")) {
      ReadCellTypes(r);
    } else if (EqualsNoCase(keyword, "METADATA")) {
      SkipMetadata(s);
    } else if (EqualsNoCase(keyword, "FIELD")) {
      SkipField(s);
    } else if (EqualsNoCase(keyword, "POINT_DATA") || EqualsNoCase(keyword, "CELL_DATA")) {
      break;
    } else {
      s.Fail("unexpected keyword ", QuoteToken(keyword), " in the dataset part");
    }
  }
  CollectTets(r);
  r.mesh.source = name;
  OrientAndValidateTetMesh(r.mesh);
  return std::move(r.mesh);
}

}  // namespace internal

TetMesh ReadVtkMesh(const std::string& path) {
  const std::string text = internal::ReadMeshFileText(path);
  return internal::ParseVtkMesh(text, path);
}

}  // namespace taut
