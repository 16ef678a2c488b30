#include "plugin/tetgen_reader.h"

#include <climits>

#include "plugin/mesh_text_scanner.h"

namespace taut {
namespace internal {
namespace {

// True if text ends with suffix.
bool EndsWith(const std::string& text, const std::string& suffix) {
  return text.size() >= suffix.size() &&
         text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// Fails unless the scanner has reached the end of its text.
void ExpectNoMoreLines(MeshTextScanner& s, long long count, const char* items) {
  if (s.NextLine())
    s.Fail("unexpected ", QuoteToken(s.PeekToken()), " after the ", count, " ", items,
           " announced on line 1");
}

// Reads the .node file into mesh.nodes; returns the first point number (0 or 1).
int ReadTetGenNodes(MeshTextScanner& s, TetMesh& mesh) {
  s.RequireLine("the .node header");
  const long long n = s.ReadIntInRange("point count", 1, INT_MAX);
  const long long dim = s.AtLineEnd() ? 3 : s.ReadInt("dimension");
  if (dim != 3) s.Fail("dimension must be 3, got ", dim);
  const long long num_attributes =
      s.AtLineEnd() ? 0 : s.ReadIntInRange("attribute count", 0, INT_MAX);
  const long long num_markers = s.AtLineEnd() ? 0 : s.ReadIntInRange("boundary marker flag", 0, 1);
  s.ExpectLineEnd("the .node header");
  mesh.nodes.reserve(s.CapReserve(n, 8));  // "i x y z\n" takes at least 8 bytes
  int first = 0;
  for (long long i = 0; i < n; ++i) {
    if (!s.NextLine())
      s.Fail("unexpected end of file after ", i, " of the ", n, " points announced on line 1");
    const long long number = s.ReadInt("point number");
    if (i == 0) {
      if (number != 0 && number != 1) s.Fail("first point number must be 0 or 1, got ", number);
      first = static_cast<int>(number);
    } else if (number != first + i) {
      s.Fail("point numbers must be consecutive: expected ", first + i, ", got ", number);
    }
    Vec3 X;
    X.x() = s.ReadDouble("x coordinate");
    X.y() = s.ReadDouble("y coordinate");
    X.z() = s.ReadDouble("z coordinate");
    const int extra = s.CountTokensLeft();
    if (extra > num_attributes + num_markers)
      s.Fail("expected at most ", num_attributes, " attributes and ", num_markers,
             " boundary markers after the coordinates, got ", extra, " values");
    for (int k = 0; k < extra; ++k) {
      if (k < num_attributes)
        s.ReadDouble("point attribute");
      else
        s.ReadInt("boundary marker");
    }
    mesh.nodes.push_back(X);
  }
  ExpectNoMoreLines(s, n, "points");
  return first;
}

// Reads the .ele file into mesh.tets, mapping node numbers starting at first to 0-based indices.
void ReadTetGenTets(MeshTextScanner& s, int first, TetMesh& mesh) {
  s.RequireLine("the .ele header");
  const long long m = s.ReadIntInRange("tetrahedron count", 1, INT_MAX);
  const long long nodes_per_tet = s.AtLineEnd() ? 4 : s.ReadInt("nodes per tetrahedron");
  if (nodes_per_tet == 10)
    s.Fail(
        "10-node (quadratic) tetrahedra are not supported; mesh with 4-node tetrahedra "
        "(tetgen without -o2)");
  if (nodes_per_tet != 4) s.Fail("nodes per tetrahedron must be 4, got ", nodes_per_tet);
  const long long num_regions = s.AtLineEnd() ? 0 : s.ReadIntInRange("region attribute flag", 0, 1);
  s.ExpectLineEnd("the .ele header");
  const long long last = first + static_cast<long long>(mesh.nodes.size()) - 1;
  mesh.tets.reserve(s.CapReserve(m, 10));  // "i a b c d\n" takes at least 10 bytes
  for (long long e = 0; e < m; ++e) {
    if (!s.NextLine())
      s.Fail("unexpected end of file after ", e, " of the ", m, " tetrahedra announced on line 1");
    s.ReadInt("tetrahedron number");
    const int left = s.CountTokensLeft();
    if (left < 4 || left > 4 + num_regions)
      s.Fail("expected 4 node indices", num_regions ? " and a region attribute" : "",
             " for a tetrahedron, got ", left, " values");
    std::array<int, 4> tet;
    for (int& node : tet)
      node = static_cast<int>(s.ReadIntInRange("node index", first, last) - first);
    if (left > 4) s.ReadDouble("region attribute");
    mesh.tets.push_back(tet);
  }
  ExpectNoMoreLines(s, m, "tetrahedra");
}

}  // namespace

TetMesh ParseTetGenMesh(std::string_view node_text, const std::string& node_name,
                        std::string_view ele_text, const std::string& ele_name) {
  TetMesh mesh;
  MeshTextScanner nodes(node_text, node_name, '#');
  const int first = ReadTetGenNodes(nodes, mesh);
  MeshTextScanner tets(ele_text, ele_name, '#');
  ReadTetGenTets(tets, first, mesh);
  mesh.source = ele_name;
  OrientAndValidateTetMesh(mesh);
  return mesh;
}

}  // namespace internal

TetMesh ReadTetGenMesh(const std::string& node_or_base_path) {
  std::string base = node_or_base_path;
  if (internal::EndsWith(base, ".node"))
    base.resize(base.size() - 5);
  else if (internal::EndsWith(base, ".ele"))
    base.resize(base.size() - 4);
  const std::string node_path = base + ".node", ele_path = base + ".ele";
  const std::string node_text = internal::ReadMeshFileText(node_path);
  const std::string ele_text = internal::ReadMeshFileText(ele_path);
  return internal::ParseTetGenMesh(node_text, node_path, ele_text, ele_path);
}

}  // namespace taut
