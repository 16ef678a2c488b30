#include "plugin/vtk_collection_writer.h"

#include <cstdio>
#include <fstream>

#include "plugin/common.h"

namespace taut {

namespace {
// Text with &, <, >, " and ' replaced by XML entities (for attribute values).
std::string EscapeXml(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out += c;
    }
  }
  return out;
}
}  // namespace

void WriteVtkCollection(const std::string& path, const std::vector<VtkCollectionEntry>& entries) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp);
    TAUT_DEMAND(out.good(), "WriteVtkCollection: cannot write '", tmp, "'");
    out << "<?xml version=\"1.0\"?>\n"
           "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
           "  <Collection>\n";
    char time[32];
    for (const VtkCollectionEntry& e : entries) {
      std::snprintf(time, sizeof(time), "%.17g", e.time);
      out << "    <DataSet timestep=\"" << time << "\" group=\"\" part=\"0\" file=\""
          << EscapeXml(e.file) << "\"/>\n";
    }
    out << "  </Collection>\n</VTKFile>\n";
    out.close();
    TAUT_DEMAND(!out.fail(), "WriteVtkCollection: writing '", tmp, "' failed");
  }
  // Replace in one step, so a reader never sees half a file.
  TAUT_DEMAND(std::rename(tmp.c_str(), path.c_str()) == 0, "WriteVtkCollection: cannot write '",
              path, "'");
}

void VtkSeriesWriter::Add(const std::string& dir, const std::string& series,
                          const std::string& file, double time) {
  const std::string path = dir + "/" + series + ".pvd";
  std::vector<VtkCollectionEntry>& entries = series_[path];
  if (!entries.empty() && entries.back().file == file)
    entries.back().time = time;
  else
    entries.push_back({time, file});
  WriteVtkCollection(path, entries);
}

const std::vector<VtkCollectionEntry>& VtkSeriesWriter::entries(const std::string& dir,
                                                                const std::string& series) const {
  static const std::vector<VtkCollectionEntry> kNone;
  auto found = series_.find(dir + "/" + series + ".pvd");
  return found == series_.end() ? kNone : found->second;
}

}  // namespace taut
