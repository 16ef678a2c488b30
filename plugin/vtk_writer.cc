#include "plugin/vtk_writer.h"

#include <charconv>
#include <fstream>

#include "plugin/mesh_file_error.h"

namespace taut {
namespace {

constexpr int kVtkTriangle = 5;
constexpr int kVtkTetra = 10;

// Appends the shortest decimal text that reads back as exactly x.
void AppendReal(std::string& out, double x) {
  char buffer[32];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof(buffer), x);
  out.append(buffer, ec == std::errc() ? end : buffer);
}

// Appends an integer.
void AppendInt(std::string& out, long long i) {
  char buffer[24];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof(buffer), i);
  out.append(buffer, ec == std::errc() ? end : buffer);
}

// Throws unless name is a usable legacy VTK array name and the array has expected entries.
void CheckField(const std::string& path, const std::string& name, std::size_t size,
                std::size_t expected, const char* per) {
  bool blank_free = !name.empty();
  for (char c : name) blank_free = blank_free && c > ' ' && c != 0x7f;
  TAUT_DEMAND(blank_free, "VTK file '", path, "': field name '", name,
              "' must be non-empty and contain no blanks or control characters");
  TAUT_DEMAND(size == expected, "VTK file '", path, "': field '", name, "' has ", size,
              " values but there are ", expected, " ", per);
}

// Appends "SCALARS name double 1" arrays.
void AppendScalars(std::string& out,
                   const std::vector<std::pair<std::string, std::vector<double>>>& arrays) {
  for (const auto& [name, values] : arrays) {
    out += "SCALARS " + name + " double 1\nLOOKUP_TABLE default\n";
    for (double v : values) {
      AppendReal(out, v);
      out += '\n';
    }
  }
}

// Writes points, cells of one type (cell c has nodes conn[npts*c .. npts*c+npts)) and fields.
void WriteGrid(const std::string& path, const std::string& title, const std::vector<Vec3>& points,
               const std::vector<int>& conn, int npts, int cell_type, const VtkFields& fields) {
  const std::size_t num_points = points.size(), num_cells = conn.size() / npts;
  for (int i : conn)
    TAUT_DEMAND(i >= 0 && static_cast<std::size_t>(i) < num_points, "VTK file '", path,
                "': cell refers to node ", i, " but there are ", num_points, " points");
  for (const auto& [name, v] : fields.point_scalars)
    CheckField(path, name, v.size(), num_points, "points");
  for (const auto& [name, v] : fields.point_vectors)
    CheckField(path, name, v.size(), num_points, "points");
  for (const auto& [name, v] : fields.cell_scalars)
    CheckField(path, name, v.size(), num_cells, "cells");
  // Header, then POINTS / CELLS / CELL_TYPES, then POINT_DATA and CELL_DATA.
  std::string out = "# vtk DataFile Version 3.0\n" + title + "\nASCII\nDATASET UNSTRUCTURED_GRID\n";
  out += "POINTS ";
  AppendInt(out, static_cast<long long>(num_points));
  out += " double\n";
  for (const Vec3& X : points) {
    for (int k = 0; k < 3; ++k) {
      AppendReal(out, X[k]);
      out += k < 2 ? ' ' : '\n';
    }
  }
  out += "CELLS " + std::to_string(num_cells) + " " + std::to_string(num_cells * (npts + 1)) + "\n";
  for (std::size_t c = 0; c < num_cells; ++c) {
    AppendInt(out, npts);
    for (int a = 0; a < npts; ++a) {
      out += ' ';
      AppendInt(out, conn[c * npts + a]);
    }
    out += '\n';
  }
  out += "CELL_TYPES " + std::to_string(num_cells) + "\n";
  for (std::size_t c = 0; c < num_cells; ++c) out += std::to_string(cell_type) + "\n";
  if (!fields.point_scalars.empty() || !fields.point_vectors.empty()) {
    out += "POINT_DATA " + std::to_string(num_points) + "\n";
    AppendScalars(out, fields.point_scalars);
    for (const auto& [name, values] : fields.point_vectors) {
      out += "VECTORS " + name + " double\n";
      for (const Vec3& v : values) {
        for (int k = 0; k < 3; ++k) {
          AppendReal(out, v[k]);
          out += k < 2 ? ' ' : '\n';
        }
      }
    }
  }
  if (!fields.cell_scalars.empty()) {
    out += "CELL_DATA " + std::to_string(num_cells) + "\n";
    AppendScalars(out, fields.cell_scalars);
  }
  // Write and check the stream after closing, so a full disk is reported too.
  std::ofstream file(path, std::ios::binary);
  if (!file) throw MeshFileError(path, 0, "cannot open file for writing");
  file.write(out.data(), static_cast<std::streamsize>(out.size()));
  file.close();
  if (!file) throw MeshFileError(path, 0, "error while writing");
}

// A one-line title (VTK allows 256 characters) naming the mesh source.
std::string MakeTitle(const std::string& what, const std::string& source) {
  std::string title = "taut " + what + " " + source.substr(0, 200);
  for (char& c : title)
    if (static_cast<unsigned char>(c) < ' ') c = ' ';
  return title;
}

}  // namespace

void WriteVtkMesh(const std::string& path, const TetMesh& mesh, const std::vector<Vec3>* positions,
                  const VtkFields& fields) {
  const std::vector<Vec3>& points = positions ? *positions : mesh.nodes;
  TAUT_DEMAND(points.size() == mesh.nodes.size(), "VTK file '", path, "': ", points.size(),
              " positions given for the ", mesh.nodes.size(), " nodes of ", mesh.source);
  // VTK order: swap nodes 0 and 1 (see the header).
  std::vector<int> conn;
  conn.reserve(4 * mesh.tets.size());
  for (const auto& t : mesh.tets) conn.insert(conn.end(), {t[1], t[0], t[2], t[3]});
  WriteGrid(path, MakeTitle("tet mesh", mesh.source), points, conn, 4, kVtkTetra, fields);
}

void WriteVtkSurface(const std::string& path, const std::vector<Vec3>& positions,
                     const std::vector<Triangle>& triangles, const VtkFields& fields) {
  std::vector<int> conn;
  conn.reserve(3 * triangles.size());
  for (const auto& t : triangles) conn.insert(conn.end(), t.begin(), t.end());
  WriteGrid(path, MakeTitle("surface", path), positions, conn, 3, kVtkTriangle, fields);
}

}  // namespace taut
