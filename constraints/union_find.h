// Disjoint sets over 0..n-1 (path halving, union by index), for building constraint islands.
#pragma once

#include <vector>

namespace taut {

// Reusable: Reset(n) keeps the storage, so a step that builds islands allocates nothing once the
// capacity suffices.
class UnionFind {
 public:
  // n singletons.
  void Reset(int n) {
    parent_.resize(n);
    for (int i = 0; i < n; ++i) parent_[i] = i;
  }
  // Representative of i's set.
  int Find(int i) {
    while (parent_[i] != i) {
      parent_[i] = parent_[parent_[i]];
      i = parent_[i];
    }
    return i;
  }
  // Joins the sets of a and b (the smaller representative wins, so results do not depend on
  // the order of calls).
  void Unite(int a, int b) {
    a = Find(a);
    b = Find(b);
    if (a == b) return;
    if (a < b) {
      parent_[b] = a;
    } else {
      parent_[a] = b;
    }
  }

 private:
  std::vector<int> parent_;
};

}  // namespace taut
