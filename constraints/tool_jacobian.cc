#include "constraints/tool_jacobian.h"

namespace taut {

Eigen::Matrix<double, 1, 6> CalcRigidPointToolRow(const Vec3& d, const Vec3& q, const Vec3& o) {
  Eigen::Matrix<double, 1, 6> row;
  row.head<3>() = -d.transpose();
  row.tail<3>() = -(q - o).cross(d).transpose();
  return row;
}

void AddPrescribedBodyToolJacobian(const IslandRows& rows, int b, ToolJacobian& J_t) {
  TAUT_DEMAND(J_t.rows() == rows.size(), "AddPrescribedBodyToolJacobian: J_t has ", J_t.rows(),
              " rows for ", rows.size(), " island rows");
  for (int c : rows.body_rows(b))
    rows[c].ForEachEntry([&](int on, int block, const Vec3& J) {
      if (on != b) return;
      TAUT_DEMAND(block == 0 || block == 1, "AddPrescribedBodyToolJacobian: row ", c, " has block ",
                  block, " on body ", b, ", which is not rigid");
      J_t.row(c).segment<3>(3 * block) += J.transpose();
    });
}

namespace {
// (3 x 6) G_n: node velocity u_lin + u_ang x r = [I, -[r]x] u for r = x_n - o.
Eigen::Matrix<double, 3, 6> CalcNodeTwistMap(const Vec3& r) {
  Eigen::Matrix<double, 3, 6> G;
  G.leftCols<3>().setIdentity();
  G.rightCols<3>() << 0.0, r.z(), -r.y(), -r.z(), 0.0, r.x(), r.y(), -r.x(), 0.0;
  return G;
}
}  // namespace

void AddDrivenNodesToolJacobian(const IslandRows& rows, int b, const DeformableBody& body,
                                const std::vector<int>& nodes, const Vec3& o, double c_K,
                                const MatX& Y_b, ToolJacobian& J_t) {
  TAUT_DEMAND(J_t.rows() == rows.size(), "AddDrivenNodesToolJacobian: J_t has ", J_t.rows(),
              " rows for ", rows.size(), " island rows");
  const int N = body.num_nodes();
  // Gather: G (3N x 6) on the driven nodes, zero elsewhere.
  MatX G = MatX::Zero(3 * N, 6);
  std::vector<char> driven(N, 0);
  for (int n : nodes) {
    TAUT_DEMAND(n >= 0 && n < N && body.node_kind(n) == NodeKind::kKinematic, "body '", body.name(),
                "': driven node ", n, " is out of range or not kinematic");
    G.middleRows<3>(3 * n) = CalcNodeTwistMap(body.node_position(n) - o);
    driven[n] = 1;
  }
  // J_k G: the rows' own entries on the driven nodes.
  for (int c : rows.body_rows(b))
    rows[c].ForEachEntry([&](int on, int block, const Vec3& J) {
      if (on == b && driven[block]) J_t.row(c) += J.transpose() * G.middleRows<3>(3 * block);
    });
  // - c_K Y^T K G: the free nodes' v* following the driven ones.
  MatX KG = MatX::Zero(3 * N, 6);
  VecX g(3 * N), out(3 * N);
  for (int j = 0; j < 6; ++j) {
    g = G.col(j);
    out.setZero();
    body.model().AddScaledStiffnessTimes(c_K, g, out);
    KG.col(j) = out;
  }
  const std::vector<int>& body_rows = rows.body_rows(b);
  const MatX YtKG = Y_b.transpose() * KG;  // (rows of b x 6)
  for (size_t i = 0; i < body_rows.size(); ++i) J_t.row(body_rows[i]) -= YtKG.row(i);
}

}  // namespace taut
