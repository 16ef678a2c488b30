#include "plugin/obj_surface_reader.h"

// The Debian library libtinyobjloader_double is built with doubles; the header must agree (the
// CMake target tinyobjloader::tinyobjloader_double also defines this).
#ifndef TINYOBJLOADER_USE_DOUBLE
#define TINYOBJLOADER_USE_DOUBLE
#endif
#include <tiny_obj_loader.h>

#include <cmath>

#include "plugin/mesh_file_error.h"
#include "plugin/mesh_text_scanner.h"

namespace taut {
namespace {

// Drops trailing blanks and line breaks from tinyobjloader's messages.
std::string TrimMessage(std::string text) {
  while (!text.empty() && static_cast<unsigned char>(text.back()) <= ' ') text.pop_back();
  return text;
}

}  // namespace

SurfaceMesh ReadObjSurface(const std::string& path) {
  const std::string text = internal::ReadMeshFileText(path);
  tinyobj::ObjReaderConfig config;
  config.triangulate = true;
  config.vertex_color = false;
  tinyobj::ObjReader reader;
  if (!reader.ParseFromString(text, "", config))
    throw MeshFileError(path, 0, "cannot parse OBJ: " + TrimMessage(reader.Error()));
  const tinyobj::attrib_t& attrib = reader.GetAttrib();
  SurfaceMesh mesh;
  mesh.source = path;
  const std::size_t num_vertices = attrib.vertices.size() / 3;
  mesh.vertices.reserve(num_vertices);
  for (std::size_t i = 0; i < num_vertices; ++i) {
    const Vec3 v(attrib.vertices[3 * i], attrib.vertices[3 * i + 1], attrib.vertices[3 * i + 2]);
    if (!v.allFinite())
      throw MeshFileError(path, 0, internal::Concat("vertex ", i, " has a non-finite coordinate"));
    mesh.vertices.push_back(v);
  }
  for (const tinyobj::shape_t& shape : reader.GetShapes()) {
    const auto& indices = shape.mesh.indices;
    std::size_t offset = 0;
    for (std::size_t f = 0; f < shape.mesh.num_face_vertices.size(); ++f) {
      const int n = shape.mesh.num_face_vertices[f];
      if (n != 3 || offset + 3 > indices.size())
        throw MeshFileError(path, 0,
                            internal::Concat("face ", f, " of shape '", shape.name, "' has ", n,
                                             " vertices after triangulation"));
      Triangle t;
      for (int a = 0; a < 3; ++a) {
        t[a] = indices[offset + a].vertex_index;
        if (t[a] < 0 || static_cast<std::size_t>(t[a]) >= num_vertices)
          throw MeshFileError(
              path, 0,
              internal::Concat("face ", f, " of shape '", shape.name, "' refers to vertex ", t[a],
                               " but the file has ", num_vertices, " vertices"));
      }
      mesh.triangles.push_back(t);
      offset += 3;
    }
  }
  if (mesh.triangles.empty()) throw MeshFileError(path, 0, "no triangles (no 'f' lines)");
  return mesh;
}

}  // namespace taut
