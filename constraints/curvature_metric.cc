#include "constraints/curvature_metric.h"

#include <Eigen/Eigenvalues>

namespace taut {

void CurvatureMetric::CollectLimitRows(double h, const std::vector<IslandBody*>& bodies,
                                       const std::vector<ConstraintSource*>& sources,
                                       const IslandRows& rows, const VecX& lambda,
                                       const std::vector<VecX>& v) {
  Clear();
  const int m = rows.size();
  weights_.setZero(m);
  bool any = false;
  for (int c = 0; c < m; ++c) {
    if (!IsLimitRow(rows[c]) || lambda[c] <= 0.0) continue;
    weights_[c] = h * lambda[c];  // d^2/dv^2 of -lambda C(x0 + h v)/h: h lambda [-d^2 C/dx^2]
    any = true;
  }
  if (!any) return;
  const IslandIterate iterate(h, bodies, v, rows.positions());
  for (const ConstraintSource* source : sources)
    source->AddIslandCurvature(iterate, rows.rows().data(), weights_.data(), m, *this);
}

void CurvatureMetric::AddBlock(int body, int node_a, int node_b, const Mat3& block) {
  node_blocks_.push_back({body, node_a, node_b, block});
}

void CurvatureMetric::AddElementBlock(int body, int element, const int* nodes,
                                      const Eigen::Ref<const MatX>& block) {
  const int k = static_cast<int>(block.rows() / 3);
  TAUT_ASSERT(k <= kMaxRowNodes && block.cols() == block.rows());
  ElementBlock& e = elements_.emplace_back();
  e.body = body;
  e.element = element;
  e.num_nodes = k;
  std::copy(nodes, nodes + k, e.nodes.begin());
  e.offset = values_.size();
  values_.resize(values_.size() + block.size());
  Eigen::Map<MatX>(values_.data() + e.offset, block.rows(), block.cols()) = block;
}

void CurvatureMetric::Clear() {
  node_blocks_.clear();
  elements_.clear();
  values_.clear();
}

Eigen::Map<const MatX> CurvatureMetric::Block(const ElementBlock& e) const {
  return Eigen::Map<const MatX>(values_.data() + e.offset, 3 * e.num_nodes, 3 * e.num_nodes);
}

namespace {
// out_e += B u_e over the element's nodes, B (3k x 3k, column-major at `block`) as the sum of
// its columns scaled by u_e: fixed-size vector operations (Eigen's general matrix-vector kernel
// costs about twice as much at these sizes).
template <int kNodes>
void AddElementBlockTimes(const double* block, const int* nodes, const VecX& u, VecX& out) {
  constexpr int n = 3 * kNodes;
  const Eigen::Map<const Eigen::Matrix<double, n, n>> B(block);
  Eigen::Matrix<double, n, 1> product = Eigen::Matrix<double, n, 1>::Zero();
  for (int j = 0; j < kNodes; ++j)
    for (int d = 0; d < 3; ++d) product += B.col(3 * j + d) * u[3 * nodes[j] + d];
  for (int a = 0; a < kNodes; ++a)
    out.segment<3>(3 * nodes[a]) += product.template segment<3>(3 * a);
}
}  // namespace

void CurvatureMetric::AddTimes(const std::vector<VecX>& u, std::vector<VecX>& out) const {
  for (const NodeBlock& g : node_blocks_)
    out[g.body].segment<3>(3 * g.a) += g.block * u[g.body].segment<3>(3 * g.b);
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 3 * kMaxRowNodes, 1> ue, ge;
  for (const ElementBlock& e : elements_) {
    const double* block = values_.data() + e.offset;
    if (e.num_nodes == 4) {  // tets
      AddElementBlockTimes<4>(block, e.nodes.data(), u[e.body], out[e.body]);
      continue;
    }
    if (e.num_nodes == 8) {  // hexes
      AddElementBlockTimes<8>(block, e.nodes.data(), u[e.body], out[e.body]);
      continue;
    }
    ue.resize(3 * e.num_nodes);
    for (int n = 0; n < e.num_nodes; ++n)
      ue.segment<3>(3 * n) = u[e.body].segment<3>(3 * e.nodes[n]);
    ge.noalias() = Block(e) * ue;
    for (int n = 0; n < e.num_nodes; ++n)
      out[e.body].segment<3>(3 * e.nodes[n]) += ge.segment<3>(3 * n);
  }
}

int CurvatureMetric::ClampIndefiniteElementBlocks() {
  // A Cholesky factor of B + delta I (delta = 1e-10 max |B_kk|) proves lambda_min(B) > -delta
  // and B stays; the others are replaced by their positive semi-definite part (negative
  // eigenvalues set to 0), which then pass the same test.
  // Element blocks are at most 3 kMaxRowNodes square: no heap allocation per block.
  using Block =
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 3 * kMaxRowNodes, 3 * kMaxRowNodes>;
  int clamped = 0;
  for (const ElementBlock& e : elements_) {
    Eigen::Map<MatX> block(values_.data() + e.offset, 3 * e.num_nodes, 3 * e.num_nodes);
    const double delta = 1e-10 * block.diagonal().cwiseAbs().maxCoeff();
    Block shifted = block;
    shifted.diagonal().array() += delta;
    if (block.isZero(0.0) || (delta > 0.0 && Eigen::LLT<Block>(shifted).info() == Eigen::Success))
      continue;
    const Eigen::SelfAdjointEigenSolver<Block> eigen{Block(block)};
    block = eigen.eigenvectors() * eigen.eigenvalues().cwiseMax(0.0).asDiagonal() *
            eigen.eigenvectors().transpose();
    ++clamped;
  }
  return clamped;
}

void CurvatureMetric::AddToNewtonMatrices(const std::vector<IslandBody*>& bodies) const {
  for (const NodeBlock& g : node_blocks_) bodies[g.body]->AddNewtonBlock(g.a, g.b, g.block);
  for (const ElementBlock& e : elements_)
    bodies[e.body]->AddNewtonElementBlock(e.element, e.nodes.data(), Block(e));
}

}  // namespace taut
