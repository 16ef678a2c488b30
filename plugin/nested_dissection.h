// Nested-dissection fill-reducing ordering of a symmetric sparse pattern, by METIS (Karypis and
// Kumar, "A fast and high quality multilevel scheme for partitioning irregular graphs", SIAM J.
// Sci. Comput. 20(1), 1998; METIS_NodeND). SparseLdlt uses it beside AMD for large bodies and keeps
// it where it saves enough factor work (docs/solver.md, "Orderings").
#pragma once

#include <Eigen/SparseCore>
#include <vector>

namespace taut {

// The elimination order new -> old (perm[k] = column of A eliminated k-th) of the symmetric pattern
// triu(A) + triu(A)^T (only entries with row <= col are read). When the size is a multiple of 3
// and `blocks_of_three` is set, the graph of 3x3 node blocks (entry (r, c) -> (r / 3, c / 3)) is
// ordered and each node's three DOFs stay adjacent, as in a body's A, whose 3x3 blocks are full:
// a graph 9x smaller and supernodes of whole nodes. Deterministic (METIS' fixed seed). Throws
// InputError for a non-square or uncompressed pattern, and when METIS reports an error.
std::vector<int> CalcNestedDissectionOrdering(const Eigen::SparseMatrix<double>& pattern,
                                              bool blocks_of_three);

}  // namespace taut
