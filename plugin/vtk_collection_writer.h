// ParaView collection files (.pvd): one time series of VTK files that ParaView opens as one
// animation.
#pragma once

#include <map>
#include <string>
#include <vector>

namespace taut {

// One dataset of a collection: a VTK file at a time.
struct VtkCollectionEntry {
  double time;       // [s] or any increasing frame value
  std::string file;  // path relative to the .pvd file's folder
};

// Writes `path` as a ParaView collection (VTKFile type="Collection") with one DataSet per entry
// (timestep, part 0, file), in the order given. File names and times are XML-escaped and written
// with 17 significant digits. Throws InputError when the file cannot be written (naming the path).
void WriteVtkCollection(const std::string& path, const std::vector<VtkCollectionEntry>& entries);

// Several collections in one folder that grow by a frame at a time, e.g. one per body of a run.
// Every Add rewrites that collection's .pvd, so a run stopped midway still opens; the files are
// small (one line per frame). Adding the file that ends a collection again updates its time
// instead of listing it twice.
class VtkSeriesWriter {
 public:
  // Adds `file` (a name inside dir) at `time` to dir/<series>.pvd and rewrites that file.
  void Add(const std::string& dir, const std::string& series, const std::string& file, double time);
  // Entries of dir/<series>.pvd so far (empty when unknown).
  const std::vector<VtkCollectionEntry>& entries(const std::string& dir,
                                                 const std::string& series) const;

 private:
  std::map<std::string, std::vector<VtkCollectionEntry>> series_;  // by .pvd path
};

}  // namespace taut
