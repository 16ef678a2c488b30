// Sparse right-hand sides, column by column: the Delassus columns J^T of the dual path touch a
// few DOFs each (a contact node's three, an element's twelve or twenty-four), so they are passed
// to the half solves as entries instead of a dense (DOFs x rows) matrix that is mostly zeros.
#pragma once

#include <vector>

namespace taut {

// Column c holds the entries [start[c], start[c + 1]) of (index, value); an index may repeat
// (the values are summed in entry order).
struct SparseColumns {
  std::vector<int> start{0};
  std::vector<int> index;
  std::vector<double> value;

  int cols() const { return static_cast<int>(start.size()) - 1; }
  void Clear() {
    start.assign(1, 0);
    index.clear();
    value.clear();
  }
  void Add(int i, double v) {
    index.push_back(i);
    value.push_back(v);
  }
  // Closes the column whose entries were added since the last call.
  void EndColumn() { start.push_back(static_cast<int>(index.size())); }
};

}  // namespace taut
