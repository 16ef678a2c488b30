#include "plugin/off_reader.h"

#include <climits>

#include "plugin/mesh_text_scanner.h"

namespace taut {
namespace internal {

SurfaceMesh ParseOffSurface(std::string_view text, const std::string& name) {
  MeshTextScanner s(text, name, '#');
  SurfaceMesh mesh;
  mesh.source = name;
  // Header: [ST][C][N]OFF, counts on the same line or the next.
  s.RequireLine("the OFF header");
  const std::string_view head = s.ReadToken("the OFF header");
  bool header_ok = head.size() >= 3 && head.substr(head.size() - 3) == "OFF";
  for (std::size_t i = 0; header_ok && i + 3 < head.size(); ++i)
    header_ok = head[i] == 'S' || head[i] == 'T' || head[i] == 'C' || head[i] == 'N';
  if (!header_ok) s.Fail("expected the header 'OFF', got ", QuoteToken(head));
  if (s.AtLineEnd()) s.RequireLine("the vertex and face counts");
  const long long num_vertices = s.ReadIntInRange("vertex count", 1, INT_MAX);
  const long long num_faces = s.ReadIntInRange("face count", 1, INT_MAX);
  if (!s.AtLineEnd()) s.ReadIntInRange("edge count", 0, LLONG_MAX);
  s.ExpectLineEnd("the counts");

  // Vertices: "x y z" then anything (colour etc.). Each takes at least 6 bytes ("0 0 0\n").
  mesh.vertices.reserve(s.CapReserve(num_vertices, 6));
  for (long long i = 0; i < num_vertices; ++i) {
    s.RequireLine("a vertex");
    const double x = s.ReadDouble("vertex x");
    const double y = s.ReadDouble("vertex y");
    const double z = s.ReadDouble("vertex z");
    mesh.vertices.emplace_back(x, y, z);
  }

  // Faces: "n i_1 ... i_n" then anything; fan triangulated. Each takes at least 8 bytes.
  mesh.triangles.reserve(s.CapReserve(num_faces, 8));
  for (long long f = 0; f < num_faces; ++f) {
    s.RequireLine("a face");
    const long long n = s.ReadIntInRange("face vertex count", 3, INT_MAX);
    const int left = s.CountTokensLeft();
    if (n > left) s.Fail("face ", f, " lists ", n, " vertices but only ", left, " values follow");
    const int first = static_cast<int>(s.ReadIntInRange("vertex index", 0, num_vertices - 1));
    int previous = static_cast<int>(s.ReadIntInRange("vertex index", 0, num_vertices - 1));
    for (long long k = 2; k < n; ++k) {
      const int next = static_cast<int>(s.ReadIntInRange("vertex index", 0, num_vertices - 1));
      if (first == previous || previous == next || next == first)
        s.Fail("face ", f, " repeats vertex ", first == previous || first == next ? first : next);
      mesh.triangles.push_back({first, previous, next});
      previous = next;
    }
  }
  if (s.NextLine()) s.Fail("unexpected data after the ", num_faces, " faces");
  return mesh;
}

}  // namespace internal

SurfaceMesh ReadOffSurface(const std::string& path) {
  const std::string text = internal::ReadMeshFileText(path);
  return internal::ParseOffSurface(text, path);
}

}  // namespace taut
