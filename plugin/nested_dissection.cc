#include "plugin/nested_dissection.h"

#include <metis.h>

#include <algorithm>

#include "plugin/common.h"

namespace taut {

namespace {

// The adjacency lists (CSR, no self loops, each edge both ways) of the graph whose vertices are
// the groups of `group` consecutive columns, with an edge where triu(A) has an entry between two
// groups.
void BuildGroupGraph(const Eigen::SparseMatrix<double>& pattern, int group,
                     std::vector<idx_t>& xadj, std::vector<idx_t>& adjncy) {
  const int n = static_cast<int>(pattern.rows()) / group;
  std::vector<std::vector<idx_t>> neighbours(n);
  const int* outer = pattern.outerIndexPtr();
  const int* inner = pattern.innerIndexPtr();
  for (int c = 0; c < pattern.cols(); ++c)
    for (int p = outer[c]; p < outer[c + 1]; ++p) {
      const int r = inner[p];
      if (r > c) continue;
      const int a = r / group, b = c / group;
      if (a == b) continue;
      neighbours[a].push_back(b);
      neighbours[b].push_back(a);
    }
  xadj.assign(n + 1, 0);
  adjncy.clear();
  for (int v = 0; v < n; ++v) {
    std::vector<idx_t>& list = neighbours[v];
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    adjncy.insert(adjncy.end(), list.begin(), list.end());
    xadj[v + 1] = static_cast<idx_t>(adjncy.size());
  }
}

}  // namespace

std::vector<int> CalcNestedDissectionOrdering(const Eigen::SparseMatrix<double>& pattern,
                                              bool blocks_of_three) {
  TAUT_DEMAND(pattern.rows() == pattern.cols(), "CalcNestedDissectionOrdering: matrix must be ",
              "square, got ", pattern.rows(), "x", pattern.cols());
  TAUT_DEMAND(pattern.isCompressed(),
              "CalcNestedDissectionOrdering: matrix must be compressed (call makeCompressed())");
  const int n = static_cast<int>(pattern.rows());
  const int group = blocks_of_three && n % 3 == 0 ? 3 : 1;
  std::vector<idx_t> xadj, adjncy;
  BuildGroupGraph(pattern, group, xadj, adjncy);
  idx_t vertices = n / group;
  std::vector<int> perm(n);
  if (vertices == 0) return perm;
  std::vector<idx_t> order(vertices), inverse(vertices);
  idx_t options[METIS_NOPTIONS];
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_NUMBERING] = 0;
  // METIS_NodeND: A(order, order) is the reordered matrix, so order[k] is the vertex placed k-th.
  const int status = METIS_NodeND(&vertices, xadj.data(), adjncy.data(), nullptr, options,
                                  order.data(), inverse.data());
  TAUT_DEMAND(status == METIS_OK, "CalcNestedDissectionOrdering: METIS_NodeND failed (status ",
              status, ") on a graph of ", vertices, " vertices");
  for (int k = 0; k < vertices; ++k)
    for (int d = 0; d < group; ++d) perm[group * k + d] = group * static_cast<int>(order[k]) + d;
  return perm;
}

}  // namespace taut
