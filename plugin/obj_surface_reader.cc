#include "plugin/obj_surface_reader.h"

// The Debian library libtinyobjloader_double is built with doubles; the header must agree (the
// CMake target tinyobjloader::tinyobjloader_double also defines this).
#ifndef TINYOBJLOADER_USE_DOUBLE
#define TINYOBJLOADER_USE_DOUBLE
#endif
#include <tiny_obj_loader.h>

#include <charconv>
#include <climits>
#include <cmath>
#include <vector>

#include "plugin/mesh_file_error.h"
#include "plugin/mesh_text_scanner.h"

namespace taut {
namespace internal {
namespace {

// tinyobjloader stores the vertex count of an untriangulated face in an unsigned char.
constexpr std::size_t kMaxFaceVertices = 255;

// What the pre-pass hands to tinyobjloader and what it reads itself.
struct ObjPrepass {
  std::string text;             // canonical "v" and "f" lines, "o" and "g" lines; others blank
  std::vector<Vec3> vertices;   // (num_vertices) x y z of the "v" lines
  std::vector<int> face_lines;  // (num_faces) 1-based line of each face, in file order
};

// Blanks between the tokens of an OBJ line, as tinyobjloader reads them.
bool IsObjBlank(char c) { return c == ' ' || c == '\t'; }

// The blank-separated tokens of a line.
std::vector<std::string_view> SplitObjTokens(std::string_view line) {
  std::vector<std::string_view> tokens;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && IsObjBlank(line[i])) ++i;
    const std::size_t begin = i;
    while (i < line.size() && !IsObjBlank(line[i])) ++i;
    if (i > begin) tokens.push_back(line.substr(begin, i - begin));
  }
  return tokens;
}

// Drops trailing blanks and line breaks from tinyobjloader's messages.
std::string TrimMessage(std::string text) {
  while (!text.empty() && static_cast<unsigned char>(text.back()) <= ' ') text.pop_back();
  return text;
}

// Throws MeshFileError "path: <reason> (line <line>)"; OBJ messages keep the "path: " prefix.
template <typename... Args>
[[noreturn]] void FailObj(const std::string& path, int line, const Args&... args) {
  throw MeshFileError(path, 0, Concat(args..., " (line ", line, ")"));
}

// Parses the x y z of a "v" line (further values, e.g. colours, are ignored): each must be a
// finite number as std::from_chars reads it (a leading '+' allowed).
Vec3 ParseObjVertex(const std::vector<std::string_view>& tokens, std::size_t vertex,
                    const std::string& path, int line) {
  if (tokens.size() < 4)
    FailObj(path, line, "vertex ", vertex, " has ", tokens.size() - 1,
            " coordinates; expected x y z");
  Vec3 X;
  for (int k = 0; k < 3; ++k) {
    const std::string_view token = tokens[k + 1];
    std::string_view digits = token;
    if (digits.size() > 1 && digits[0] == '+') digits.remove_prefix(1);
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), X[k]);
    if (ec == std::errc::result_out_of_range || (ec == std::errc() && !std::isfinite(X[k])))
      FailObj(path, line, "vertex ", vertex, " has a non-finite coordinate ", QuoteToken(token));
    if (ec != std::errc() || end != digits.data() + digits.size())
      FailObj(path, line, "vertex ", vertex, ": expected a number, got ", QuoteToken(token));
  }
  return X;
}

// Appends the vertex indices of an "f" line (3 to 255 references "i", "i/t", "i//n" or "i/t/n",
// each i an integer that fits in an int) to out as " i_1 ... i_n".
void AppendObjFace(const std::vector<std::string_view>& tokens, std::size_t face,
                   const std::string& path, int line, std::string& out) {
  const std::size_t n = tokens.size() - 1;
  if (n < 3 || n > kMaxFaceVertices)
    FailObj(path, line, "face ", face, " has ", n, " vertices; expected 3 to ", kMaxFaceVertices);
  for (std::size_t k = 1; k <= n; ++k) {
    const std::string_view token = tokens[k];
    std::string_view digits = token.substr(0, token.find('/'));
    if (digits.size() > 1 && digits[0] == '+') digits.remove_prefix(1);
    int index = 0;
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), index);
    if (ec == std::errc::result_out_of_range)
      FailObj(path, line, "face ", face, ": vertex index ", QuoteToken(token), " is too large");
    if (ec != std::errc() || end != digits.data() + digits.size())
      FailObj(path, line, "face ", face, ": expected a vertex index, got ", QuoteToken(token));
    out += ' ';
    out += std::to_string(index);
  }
}

// Splits text into lines the way tinyobjloader does ("\n", "\r\n" or "\r"; a NUL byte ends a
// line's text), reads the vertices and checks the faces itself, and hands tinyobjloader only
// placeholder "v 0 0 0" and canonical "f i_1 ... i_n" lines plus the "o" and "g" lines.
// tinyobjloader then resolves the (relative) indices and groups, but never parses a number this
// reader has not checked: on arbitrary bytes its own number parsing overflows (an exponent past
// INT_MAX, an unchecked real converted to int in "vw" lines). Other lines are left blank, so line
// numbers stay those of the file.
ObjPrepass PrepareObjText(std::string_view text, const std::string& path) {
  ObjPrepass out;
  out.text.reserve(text.size());
  std::size_t pos = 0;
  int line_number = 0;
  while (pos < text.size()) {
    std::size_t end = pos;
    while (end < text.size() && text[end] != '\n' && text[end] != '\r') ++end;
    std::string_view line = text.substr(pos, end - pos);
    pos = end + (end + 1 < text.size() && text[end] == '\r' && text[end + 1] == '\n' ? 2 : 1);
    if (line_number < INT_MAX) ++line_number;
    line = line.substr(0, line.find('\0'));
    const std::vector<std::string_view> tokens = SplitObjTokens(line);
    const std::string_view kind = tokens.empty() ? std::string_view() : tokens[0];
    if (kind == "v") {
      out.vertices.push_back(ParseObjVertex(tokens, out.vertices.size(), path, line_number));
      out.text += "v 0 0 0";  // tinyobjloader only counts vertices (for relative indices)
    } else if (kind == "f") {
      out.text += 'f';
      AppendObjFace(tokens, out.face_lines.size(), path, line_number, out.text);
      out.face_lines.push_back(line_number);
    } else if (kind == "o" || kind == "g") {
      out.text.append(line);
    }
    out.text += '\n';
  }
  return out;
}

}  // namespace

SurfaceMesh ParseObjSurface(std::string_view text, const std::string& path) {
  const ObjPrepass prepass = PrepareObjText(text, path);
  tinyobj::ObjReaderConfig config;
  config.triangulate = false;  // fan-triangulated below, like the OFF reader
  config.vertex_color = false;
  tinyobj::ObjReader reader;
  if (!reader.ParseFromString(prepass.text, "", config))
    throw MeshFileError(path, 0, "cannot parse OBJ: " + TrimMessage(reader.Error()));
  SurfaceMesh mesh;
  mesh.source = path;
  mesh.vertices = prepass.vertices;
  const std::size_t num_vertices = mesh.vertices.size();
  if (reader.GetAttrib().vertices.size() != 3 * num_vertices)
    throw MeshFileError(path, 0,
                        Concat("tinyobjloader read ", reader.GetAttrib().vertices.size() / 3,
                               " vertices where this reader found ", num_vertices));
  // Faces in file order (shapes follow each other); polygon (i_1 ... i_n) becomes the fan
  // (i_1, i_k, i_k+1), keeping its winding.
  std::size_t face = 0;
  for (const tinyobj::shape_t& shape : reader.GetShapes()) {
    const auto& indices = shape.mesh.indices;
    std::size_t offset = 0;
    for (std::size_t f = 0; f < shape.mesh.num_face_vertices.size(); ++f, ++face) {
      const int line = face < prepass.face_lines.size() ? prepass.face_lines[face] : 0;
      const std::size_t n = shape.mesh.num_face_vertices[f];
      if (n < 3 || offset + n > indices.size())
        FailObj(path, line, "face ", face, " of shape '", shape.name, "' has ", n, " vertices");
      std::vector<int> polygon(n);
      for (std::size_t a = 0; a < n; ++a) {
        polygon[a] = indices[offset + a].vertex_index;
        if (polygon[a] < 0 || static_cast<std::size_t>(polygon[a]) >= num_vertices)
          FailObj(path, line, "face ", face, " of shape '", shape.name, "' refers to vertex ",
                  polygon[a], " but the file has ", num_vertices, " vertices");
      }
      for (std::size_t k = 1; k + 1 < n; ++k) {
        const Triangle t{polygon[0], polygon[k], polygon[k + 1]};
        if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0])
          FailObj(path, line, "face ", face, " of shape '", shape.name, "' repeats vertex ",
                  t[0] == t[1] || t[0] == t[2] ? t[0] : t[1]);
        mesh.triangles.push_back(t);
      }
      offset += n;
    }
  }
  if (mesh.triangles.empty()) throw MeshFileError(path, 0, "no triangles (no 'f' lines)");
  return mesh;
}

}  // namespace internal

SurfaceMesh ReadObjSurface(const std::string& path) {
  const std::string text = internal::ReadMeshFileText(path);
  return internal::ParseObjSurface(text, path);
}

}  // namespace taut
