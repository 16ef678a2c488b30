#include "plugin/gmsh_reader.h"

#include <algorithm>
#include <array>
#include <climits>
#include <map>
#include <set>
#include <unordered_map>

#include "plugin/mesh_text_scanner.h"

namespace taut {
namespace internal {
namespace {

constexpr int kGmshTet4 = 4;    // 4-node tetrahedron
constexpr int kGmshTet10 = 11;  // 10-node tetrahedron

// Parse state shared by the section readers.
struct GmshReader {
  MeshTextScanner s;
  TetMesh mesh;
  std::unordered_map<long long, int> node_index;  // node tag -> index into mesh.nodes
  std::set<std::array<int, 4>> tet_keys;          // sorted node indices of the kept tets
  std::map<long long, long long> skipped;         // element type -> count of skipped elements
  int nodes_line = 0;                             // line of "$Nodes", 0 before it
  int elements_line = 0;                          // line of "$Elements", 0 before it
};

// A readable name for the common Gmsh element types used in messages.
const char* GmshTypeName(long long type) {
  switch (type) {
    case 1:
      return " (2-node line)";
    case 2:
      return " (3-node triangle)";
    case 3:
      return " (4-node quadrangle)";
    case 5:
      return " (8-node hexahedron)";
    case 6:
      return " (6-node prism)";
    case 7:
      return " (5-node pyramid)";
    case kGmshTet10:
      return " (10-node tetrahedron, not supported)";
    case 15:
      return " (1-node point)";
    default:
      return "";
  }
}

// Moves to the next data line of a section, failing on end of file or a premature "$End...".
void RequireDataLine(GmshReader& r, long long done, long long count, const char* items,
                     int header_line) {
  MeshTextScanner& s = r.s;
  if (!s.NextLine())
    s.Fail("unexpected end of file after ", done, " of the ", count, " ", items,
           " announced on line ", header_line);
  const std::string_view token = s.PeekToken();
  if (token[0] == '$')
    s.Fail("found ", QuoteToken(token), " after only ", done, " of the ", count, " ", items,
           " announced on line ", header_line);
}

// Reads the line that must close a section, e.g. "$EndNodes"; context says what came before.
void ExpectSectionEnd(GmshReader& r, const char* end, const std::string& context) {
  MeshTextScanner& s = r.s;
  if (!s.NextLine()) s.Fail("unexpected end of file while looking for ", end, " after ", context);
  const std::string_view token = s.ReadToken(end);
  if (token != end) s.Fail("expected ", end, " after ", context, ", got ", QuoteToken(token));
  s.ExpectLineEnd(end);
}

// "the <count> <items> announced on line <line>", for messages.
std::string Announced(long long count, const char* items, int line) {
  return Concat("the ", count, " ", items, " announced on line ", line);
}

// Skips a section up to its "$End<name>" line.
void SkipSection(GmshReader& r, std::string_view header) {
  MeshTextScanner& s = r.s;
  const int open_line = s.line_number();
  const std::string end = "$End" + std::string(header.substr(1));
  while (s.NextLine())
    if (s.ReadToken("a line") == end) return;
  s.Fail("unexpected end of file: section ", QuoteToken(header), " opened on line ", open_line,
         " has no ", QuoteToken(end));
}

// Reads "$MeshFormat" and its version line; returns the major version (2 or 4).
int ReadMeshFormat(GmshReader& r) {
  MeshTextScanner& s = r.s;
  if (!s.NextLine()) s.Fail("empty file; expected a Gmsh .msh file starting with $MeshFormat");
  const std::string_view first = s.ReadToken("$MeshFormat");
  if (first != "$MeshFormat")
    s.Fail("expected $MeshFormat on the first line of a Gmsh .msh file, got ", QuoteToken(first));
  s.RequireLine("the $MeshFormat version line");
  const std::string_view version = s.PeekToken();
  const double v = s.ReadDouble("format version");
  const long long file_type = s.ReadInt("file type");
  s.ReadInt("data size");
  s.ExpectLineEnd("the format version line");
  if (file_type == 1) s.Fail("binary .msh not supported; save the mesh as ASCII");
  if (file_type != 0) s.Fail("file type must be 0 (ASCII), got ", file_type);
  const bool v2 = v == 2.0 || v == 2.1 || v == 2.2;
  if (!v2 && v != 4.1)
    s.Fail("unsupported .msh version ", QuoteToken(version), "; supported: ASCII 2.2 and 4.1");
  ExpectSectionEnd(r, "$EndMeshFormat", "the format version line");
  return v2 ? 2 : 4;
}

// Records a node under its tag; a tag may be defined once.
void AddNode(GmshReader& r, long long tag, const Vec3& X) {
  const int index = static_cast<int>(r.mesh.nodes.size());
  if (!r.node_index.emplace(tag, index).second) r.s.Fail("node tag ", tag, " is defined twice");
  r.mesh.nodes.push_back(X);
}

// Reads the x y z of a node line.
Vec3 ReadPoint(MeshTextScanner& s) {
  Vec3 X;
  X.x() = s.ReadDouble("x coordinate");
  X.y() = s.ReadDouble("y coordinate");
  X.z() = s.ReadDouble("z coordinate");
  return X;
}

// Reads the 4 node tags left on the current line and stores the tet unless it is a duplicate.
void ReadTet(GmshReader& r) {
  MeshTextScanner& s = r.s;
  const int left = s.CountTokensLeft();
  if (left != 4) s.Fail("expected 4 node tags for a tetrahedron, got ", left);
  std::array<int, 4> tet;
  for (int& node : tet) {
    const long long tag = s.ReadInt("node tag");
    const auto it = r.node_index.find(tag);
    if (it == r.node_index.end()) s.Fail("node tag ", tag, " is not defined in $Nodes");
    node = it->second;
  }
  std::array<int, 4> key = tet;
  std::sort(key.begin(), key.end());
  if (r.tet_keys.insert(key).second) r.mesh.tets.push_back(tet);
}

// Reads a version 2.2 $Nodes section: "<count>", then "<tag> <x> <y> <z>" per node.
void ReadNodes2(GmshReader& r) {
  MeshTextScanner& s = r.s;
  s.RequireLine("the node count");
  const long long n = s.ReadIntInRange("node count", 0, INT_MAX);
  s.ExpectLineEnd("the node count");
  const int header_line = s.line_number();
  r.mesh.nodes.reserve(s.CapReserve(n, 8));
  for (long long i = 0; i < n; ++i) {
    RequireDataLine(r, i, n, "nodes", header_line);
    const long long tag = s.ReadIntInRange("node tag", 0, LLONG_MAX);
    const Vec3 X = ReadPoint(s);
    s.ExpectLineEnd("the node coordinates");
    AddNode(r, tag, X);
  }
  ExpectSectionEnd(r, "$EndNodes", Announced(n, "nodes", header_line));
}

// Reads a version 2.2 $Elements section: "<count>", then per element
// "<tag> <type> <#tags> <tags...> <node tags...>".
void ReadElements2(GmshReader& r) {
  MeshTextScanner& s = r.s;
  s.RequireLine("the element count");
  const long long n = s.ReadIntInRange("element count", 0, INT_MAX);
  s.ExpectLineEnd("the element count");
  const int header_line = s.line_number();
  r.mesh.tets.reserve(s.CapReserve(n, 16));
  for (long long i = 0; i < n; ++i) {
    RequireDataLine(r, i, n, "elements", header_line);
    s.ReadInt("element tag");
    const long long type = s.ReadInt("element type");
    const long long num_tags = s.ReadIntInRange("tag count", 0, INT_MAX);
    if (num_tags > s.CountTokensLeft())
      s.Fail("element declares ", num_tags, " tags but its line holds only ", s.CountTokensLeft(),
             " more values");
    for (long long k = 0; k < num_tags; ++k) s.ReadInt("element tag value");
    if (type == kGmshTet4)
      ReadTet(r);
    else
      ++r.skipped[type];
  }
  ExpectSectionEnd(r, "$EndElements", Announced(n, "elements", header_line));
}

// Reads a version 4.1 $Nodes section: "<#blocks> <#nodes> <min tag> <max tag>", then per block
// "<dim> <entity> <parametric> <#nodes>", its node tags (one per line), then its coordinates.
void ReadNodes4(GmshReader& r) {
  MeshTextScanner& s = r.s;
  s.RequireLine("the $Nodes header");
  const long long num_blocks = s.ReadIntInRange("node block count", 0, INT_MAX);
  const long long n = s.ReadIntInRange("node count", 0, INT_MAX);
  const long long min_tag = s.ReadInt("minimum node tag");
  const long long max_tag = s.ReadInt("maximum node tag");
  s.ExpectLineEnd("the $Nodes header");
  const int header_line = s.line_number();
  r.mesh.nodes.reserve(s.CapReserve(n, 8));
  std::vector<long long> tags;
  long long total = 0;
  for (long long b = 0; b < num_blocks; ++b) {
    RequireDataLine(r, b, num_blocks, "node blocks", header_line);
    const long long dim = s.ReadIntInRange("entity dimension", 0, 3);
    s.ReadInt("entity tag");
    const long long parametric = s.ReadIntInRange("parametric flag", 0, 1);
    const long long count = s.ReadIntInRange("block node count", 0, INT_MAX);
    if (count > n - total)
      s.Fail("node blocks hold more nodes than the ", n, " announced on line ", header_line);
    s.ExpectLineEnd("the node block header");
    tags.clear();
    tags.reserve(s.CapReserve(count, 8));
    for (long long i = 0; i < count; ++i) {
      RequireDataLine(r, total + i, n, "nodes", header_line);
      tags.push_back(s.ReadIntInRange("node tag", min_tag, max_tag));
      s.ExpectLineEnd("the node tag");
    }
    for (long long i = 0; i < count; ++i) {
      RequireDataLine(r, total + i, n, "node coordinates", header_line);
      const Vec3 X = ReadPoint(s);
      for (long long k = 0; k < parametric * dim; ++k) s.ReadDouble("parametric coordinate");
      s.ExpectLineEnd("the node coordinates");
      AddNode(r, tags[i], X);
    }
    total += count;
  }
  if (total != n)
    throw MeshFileError(s.name(), header_line,
                        Concat("announces ", n,
                               " nodes but the node blocks "
                               "up to line ",
                               s.line_number(), " hold ", total));
  ExpectSectionEnd(r, "$EndNodes", Announced(num_blocks, "node blocks", header_line));
}

// Reads a version 4.1 $Elements section: "<#blocks> <#elements> <min tag> <max tag>", then per
// block "<dim> <entity> <type> <#elements>" and one "<tag> <node tags...>" line per element.
void ReadElements4(GmshReader& r) {
  MeshTextScanner& s = r.s;
  s.RequireLine("the $Elements header");
  const long long num_blocks = s.ReadIntInRange("element block count", 0, INT_MAX);
  const long long n = s.ReadIntInRange("element count", 0, INT_MAX);
  const long long min_tag = s.ReadInt("minimum element tag");
  const long long max_tag = s.ReadInt("maximum element tag");
  s.ExpectLineEnd("the $Elements header");
  const int header_line = s.line_number();
  r.mesh.tets.reserve(s.CapReserve(n, 10));
  long long total = 0;
  for (long long b = 0; b < num_blocks; ++b) {
    RequireDataLine(r, b, num_blocks, "element blocks", header_line);
    s.ReadIntInRange("entity dimension", 0, 3);
    s.ReadInt("entity tag");
    const long long type = s.ReadInt("element type");
    const long long count = s.ReadIntInRange("block element count", 0, INT_MAX);
    if (count > n - total)
      s.Fail("element blocks hold more elements than the ", n, " announced on line ", header_line);
    s.ExpectLineEnd("the element block header");
    for (long long i = 0; i < count; ++i) {
      RequireDataLine(r, total + i, n, "elements", header_line);
      s.ReadIntInRange("element tag", min_tag, max_tag);
      if (type == kGmshTet4)
        ReadTet(r);
      else
        ++r.skipped[type];
    }
    total += count;
  }
  if (total != n)
    throw MeshFileError(s.name(), header_line,
                        Concat("announces ", n,
                               " elements but the element "
                               "blocks up to line ",
                               s.line_number(), " hold ", total));
  ExpectSectionEnd(r, "$EndElements", Announced(num_blocks, "element blocks", header_line));
}

// Fails at the $Elements line listing the element types found instead of tets.
[[noreturn]] void FailNoTets(GmshReader& r) {
  std::string found;
  for (const auto& [type, count] : r.skipped)
    found += Concat(found.empty() ? "" : ", ", count, " of type ", type, GmshTypeName(type));
  throw MeshFileError(r.s.name(), r.elements_line,
                      "no 4-node tetrahedra (element type 4) in $Elements; found " +
                          (found.empty() ? std::string("no elements") : found));
}

}  // namespace

TetMesh ParseGmshMesh(std::string_view text, const std::string& name) {
  GmshReader r{MeshTextScanner(text, name), {}, {}, {}, {}, 0, 0};
  MeshTextScanner& s = r.s;
  const int version = ReadMeshFormat(r);
  while (s.NextLine()) {
    const std::string_view header = s.ReadToken("a section header");
    if (header[0] != '$')
      s.Fail("expected a section header such as $Nodes, got ", QuoteToken(header));
    s.ExpectLineEnd("the section header");
    if (header == "$Nodes") {
      if (r.nodes_line) s.Fail("second $Nodes section; the first is on line ", r.nodes_line);
      r.nodes_line = s.line_number();
      version == 2 ? ReadNodes2(r) : ReadNodes4(r);
    } else if (header == "$Elements") {
      if (!r.nodes_line) s.Fail("$Elements comes before $Nodes");
      if (r.elements_line)
        s.Fail("second $Elements section; the first is on line ", r.elements_line);
      r.elements_line = s.line_number();
      version == 2 ? ReadElements2(r) : ReadElements4(r);
    } else if (header == "$MeshFormat" || header.substr(0, 4) == "$End") {
      s.Fail("unexpected ", QuoteToken(header));
    } else {
      SkipSection(r, header);
    }
  }
  if (!r.elements_line) s.Fail("end of file reached without an $Elements section");
  if (r.mesh.tets.empty()) FailNoTets(r);
  r.mesh.source = name;
  OrientAndValidateTetMesh(r.mesh);
  return std::move(r.mesh);
}

}  // namespace internal

TetMesh ReadGmshMesh(const std::string& path) {
  const std::string text = internal::ReadMeshFileText(path);
  return internal::ParseGmshMesh(text, path);
}

}  // namespace taut
