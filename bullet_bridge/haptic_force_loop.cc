#include "bullet_bridge/haptic_force_loop.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

#include "bullet_bridge/eigen_bullet.h"
#include "bullet_bridge/rigid_island_body.h"
#include "constraints/row_key_layouts.h"
#include "constraints/tool_jacobian.h"

namespace taut {

namespace {
// Query tolerance: the step's own PGS tolerance, at most this (units of w, m/s per row).
constexpr double kMaxQueryTolerance = 1e-6;

// True when contact row c (body2 < 0: a static or kinematic partner) names `tool` in its key.
bool IsToolContact(const ConstraintRow& row, const btCollisionObject* tool,
                   const btCollisionObjectArray& objects) {
  if (row.type != RowType::kContact || row.body2 >= 0) return false;
  const auto fields = UnpackRowKeyPayload(kRigidContactRowKey, RowKeyPayload(row.key));
  const bool outside_world = fields[1] != 0;
  const int index = static_cast<int>(fields[2]);
  return !outside_world && index < objects.size() && objects[index] == tool;
}

// sum_n J_n over side A (the row direction times the point's weight sum).
Vec3 SumSideA(const ConstraintRow& row) {
  Vec3 sum = Vec3::Zero();
  for (int n = 0; n < row.num_nodes; ++n) sum += row.J[n];
  return sum;
}

// Stage: J_t rows of the contacts with the tool (eq. H4): normal row c and its friction rows at
// the tool's point q = p - gap n, p the weighted contact point on the body.
void AddToolContactRows(const IslandRows& rows, const btCollisionObject* tool,
                        const btCollisionObjectArray& objects, const Vec3& o, ToolJacobian& J_t) {
  for (int c = 0; c < rows.size(); ++c) {
    const ConstraintRow& row = rows[c];
    if (row.friction_of != 0 || !IsToolContact(row, tool, objects)) continue;
    const Vec3 sum = SumSideA(row);
    const double weight = sum.norm();
    const Vec3 n = sum / weight;
    Vec3 p = Vec3::Zero();
    for (int k = 0; k < row.num_nodes; ++k)
      p += row.J[k].dot(n) / weight * rows.x(row.body).segment<3>(3 * row.nodes[k]);
    const Vec3 q = p - row.C * n;
    J_t.row(c) += CalcRigidPointToolRow(n, q, o);
    for (int k = 1; k <= 2 && c + k < rows.size() && rows[c + k].friction_of == k; ++k)
      J_t.row(c + k) += CalcRigidPointToolRow(SumSideA(rows[c + k]) / weight, q, o);
  }
}

// The island index of a dynamic tool's rigid island body, or -1.
int FindToolBody(const std::vector<IslandBody*>& bodies, const btRigidBody* tool) {
  for (size_t b = 0; b < bodies.size(); ++b) {
    const auto* rigid = dynamic_cast<const RigidIslandBody*>(bodies[b]);
    if (rigid != nullptr && rigid->rigid() == tool) return static_cast<int>(b);
  }
  return -1;
}

// Stage: J_t rows of the island's deformables' kinematic nodes pinned to the tool (eq. H5).
void AddDrivenNodeRows(const DeformableWorld& world, const std::vector<IslandBody*>& bodies,
                       const IslandRows& rows, const btRigidBody* tool, double h, const Vec3& o,
                       const std::vector<MatX>& Y, ToolJacobian& J_t) {
  for (int b = 0; b < static_cast<int>(bodies.size()); ++b) {
    const DeformableBody* body = bodies[b]->deformable();
    if (body == nullptr) continue;
    const std::vector<int> nodes = world.driven_nodes(body, tool);
    if (nodes.empty()) continue;
    const double c_K = h * body->settings().stiffness_damping + h * h;
    AddDrivenNodesToolJacobian(rows, b, *body, nodes, o, c_K, Y[b], J_t);
  }
}
}  // namespace

HapticForceLoop HapticForceLoop::Capture(DeformableWorld& world, const btRigidBody* tool) {
  TAUT_DEMAND(tool != nullptr && tool->getWorldArrayIndex() >= 0 &&
                  tool->getWorldArrayIndex() < world.getNumCollisionObjects() &&
                  world.getCollisionObjectArray()[tool->getWorldArrayIndex()] == tool,
              "HapticForceLoop::Capture: the tool is not a rigid body of this world");
  HapticForceLoop loop;
  loop.h_ = world.last_substep_forces().h;
  loop.tool_transform_ = tool->getWorldTransform();
  loop.reference_ = ToEigen(tool->getCenterOfMassPosition());
  loop.pgs_ = world.solver_settings().pgs;
  loop.pgs_.tolerance = std::min(loop.pgs_.tolerance, kMaxQueryTolerance);
  // Freeze each solved island the tool moves (a nonzero J_t row).
  std::vector<FrozenIsland> islands;
  std::vector<ToolJacobian> jacobians;
  for (const DeformableWorld::SolvedIsland& solved : world.last_solved_islands()) {
    const IslandRows& rows = *solved.rows;
    const int prescribed = FindToolBody(*solved.bodies, tool);
    FrozenIsland island =
        FreezeIsland(loop.h_, *solved.bodies, rows, *solved.multipliers, prescribed);
    ToolJacobian J_t = ToolJacobian::Zero(rows.size(), 6);
    if (prescribed >= 0) AddPrescribedBodyToolJacobian(rows, prescribed, J_t);
    AddToolContactRows(rows, tool, world.getCollisionObjectArray(), loop.reference_, J_t);
    AddDrivenNodeRows(world, *solved.bodies, rows, tool, loop.h_, loop.reference_, island.Y, J_t);
    const int tool_rows = static_cast<int>((J_t.array() != 0.0).rowwise().any().count());
    if (tool_rows == 0) continue;
    loop.num_tool_rows_ += tool_rows;
    islands.push_back(std::move(island));
    jacobians.push_back(std::move(J_t));
  }
  loop.num_islands_ = static_cast<int>(islands.size());
  loop.lcp_ = StackFrozenIslands(islands, jacobians);
  return loop;
}

HapticWrench HapticForceLoop::CalcToolWrench(const ToolMotion& motion) {
  const auto start = std::chrono::steady_clock::now();
  HapticWrench wrench;
  if (lcp_.size() == 0) return wrench;  // the tool acts on nothing
  ToolTwist u;
  u << motion.displacement / h_, motion.rotation / h_;
  const FrozenIslandLcp::Result result = lcp_.Solve(u, pgs_);
  wrench.force = result.impulse.head<3>() / h_;
  wrench.torque = result.impulse.tail<3>() / h_;
  wrench.sweeps = result.pgs.sweeps;
  wrench.residual = result.pgs.residual;
  wrench.converged = result.pgs.converged;
  wrench.microseconds =
      std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
  return wrench;
}

HapticWrench HapticForceLoop::CalcToolWrench(const btTransform& tool_now) {
  // Displacement of the reference point, and the rotation R_now R_capture^T as a rotation vector.
  ToolMotion motion;
  const btTransform& then = tool_transform_;
  motion.displacement = ToEigen(tool_now * then.invXform(ToBullet(reference_))) - reference_;
  btQuaternion turn = tool_now.getRotation() * then.getRotation().inverse();
  if (turn.getW() < 0) turn = -turn;  // the shorter way round
  const Vec3 v(turn.getX(), turn.getY(), turn.getZ());
  const double s = v.norm();
  if (s > 0.0) motion.rotation = v / s * (2.0 * std::atan2(s, static_cast<double>(turn.getW())));
  return CalcToolWrench(motion);
}

}  // namespace taut
