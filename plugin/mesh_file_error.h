// Error thrown by the mesh file readers: names the file, the 1-based line and what is wrong.
#pragma once

#include <string>

#include "plugin/common.h"

namespace taut {

// A mesh file that cannot be read or parsed. what() reads "file:line: reason", e.g.
// "beam.msh:42: expected 4 node tags for a tetrahedron, got 3", or "file: reason" when the
// problem concerns the file as a whole (line 0, e.g. "cannot open").
class MeshFileError : public InputError {
 public:
  // Builds the message from the file name, the 1-based line (0 = whole file) and the reason.
  MeshFileError(const std::string& file, int line, const std::string& reason)
      : InputError(line > 0 ? file + ":" + std::to_string(line) + ": " + reason
                            : file + ": " + reason),
        file_(file),
        line_(line),
        reason_(reason) {}

  // Path of the file as given to the reader.
  const std::string& file() const { return file_; }
  // 1-based line number of the problem; 0 when it concerns the whole file.
  int line() const { return line_; }
  // What is wrong, without the file and line prefix.
  const std::string& reason() const { return reason_; }

 private:
  std::string file_;
  int line_;
  std::string reason_;
};

}  // namespace taut
