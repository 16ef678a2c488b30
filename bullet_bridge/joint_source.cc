#include "bullet_bridge/joint_source.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "bullet_bridge/eigen_bullet.h"

namespace taut {

namespace {
// The memory layout getInfo2 writes into: per row four 3-vectors and four scalars, each field
// strided by rowskip scalars (as btSolverConstraint is for Bullet's own solver).
struct Info2Row {
  btVector3 j1_linear, j1_angular, j2_linear, j2_angular;
  btScalar rhs, cfm, lo, hi;
};
static_assert(sizeof(Info2Row) % sizeof(btScalar) == 0, "rows are whole scalars");
constexpr int kMaxJointRows = 6;  // Bullet's joints have at most 6 rows

// J v of one side (lin, ang) for island body r.
double SideVelocity(const IslandIterate& iterate, const RigidIslandBody* r, const Vec3& lin,
                    const Vec3& ang) {
  if (r == nullptr) return 0.0;
  const VecX& v = iterate.v(iterate.IndexOf(r));
  return lin.dot(v.head<3>()) + ang.dot(v.tail<3>());
}
}  // namespace

void JointSource::AddJoint(btTypedConstraint& joint, const RigidIslandBody* a,
                           const RigidIslandBody* b, const btContactSolverInfo& info) {
  if (!joint.isEnabled()) return;
  btTypedConstraint::btConstraintInfo1 info1;
  joint.getInfo1(&info1);
  const int n = std::min(info1.m_numConstraintRows, kMaxJointRows);
  if (n <= 0) return;
  Info2Row buffer[kMaxJointRows];
  for (Info2Row& row : buffer) {
    row.j1_linear.setZero();
    row.j1_angular.setZero();
    row.j2_linear.setZero();
    row.j2_angular.setZero();
    row.rhs = 0;
    row.cfm = info.m_globalCfm;
    row.lo = -SIMD_INFINITY;
    row.hi = SIMD_INFINITY;
  }
  btTypedConstraint::btConstraintInfo2 info2;
  info2.fps = btScalar(1) / info.m_timeStep;
  info2.erp = info.m_erp;
  info2.m_J1linearAxis = &buffer[0].j1_linear[0];
  info2.m_J1angularAxis = &buffer[0].j1_angular[0];
  info2.m_J2linearAxis = &buffer[0].j2_linear[0];
  info2.m_J2angularAxis = &buffer[0].j2_angular[0];
  info2.rowskip = sizeof(Info2Row) / sizeof(btScalar);
  info2.m_constraintError = &buffer[0].rhs;
  info2.cfm = &buffer[0].cfm;
  info2.m_lowerLimit = &buffer[0].lo;
  info2.m_upperLimit = &buffer[0].hi;
  info2.m_numIterations = info.m_numIterations;
  info2.m_damping = info.m_damping;
  joint.getInfo2(&info2);
  const int joint_id = joint.getUserConstraintId() >= 0 ? joint.getUserConstraintId() : 0;
  for (int r = 0; r < n; ++r) {
    JointRow row;
    row.a = a;
    row.b = b;
    row.J[0] = ToEigen(buffer[r].j1_linear);
    row.J[1] = ToEigen(buffer[r].j1_angular);
    row.J[2] = ToEigen(buffer[r].j2_linear);
    row.J[3] = ToEigen(buffer[r].j2_angular);
    row.rhs = static_cast<double>(buffer[r].rhs);
    const double breaking = static_cast<double>(joint.getBreakingImpulseThreshold());
    row.lo = std::isinf(static_cast<double>(buffer[r].lo)) || buffer[r].lo <= -SIMD_INFINITY
                 ? -std::numeric_limits<double>::infinity()
                 : static_cast<double>(buffer[r].lo);
    row.hi = buffer[r].hi >= SIMD_INFINITY ? std::numeric_limits<double>::infinity()
                                           : static_cast<double>(buffer[r].hi);
    row.lo = std::max(row.lo, -breaking);
    row.hi = std::min(row.hi, breaking);
    row.key = key_.Pack(joint_id, rows_.size());
    rows_.push_back(row);
  }
}

double JointSource::CalcC(const IslandIterate& iterate, const JointRow& row) const {
  const double jv = SideVelocity(iterate, row.a, row.J[0], row.J[1]) +
                    SideVelocity(iterate, row.b, row.J[2], row.J[3]);
  return iterate.h() * (jv - row.rhs);
}

double JointSource::CalcViolation(const IslandIterate& iterate, const JointRow& row) const {
  const double c = CalcC(iterate, row);
  if (row.lo == 0.0 && std::isinf(row.hi)) return std::max(0.0, -c);
  return std::isinf(row.lo) && std::isinf(row.hi) ? std::abs(c) : 0.0;
}

int JointSource::AppendIslandRows(const IslandIterate& iterate, std::vector<ConstraintRow>& rows) {
  for (const JointRow& joint_row : rows_) {
    ConstraintRow& row = rows.emplace_back();
    row.key = joint_row.key;
    row.C = CalcC(iterate, joint_row);
    row.type = RowType::kJoint;
    row.bilateral = !(joint_row.lo == 0.0 && std::isinf(joint_row.hi));
    row.lo = joint_row.lo;
    row.hi = joint_row.hi;
    // Side A on the first coupled body, side B on the other (an uncoupled side is left out).
    const RigidIslandBody* sides[2] = {joint_row.a, joint_row.b};
    for (int s = 0; s < 2; ++s) {
      if (sides[s] == nullptr) continue;
      const bool first = row.num_nodes == 0;
      (first ? row.body : row.body2) = iterate.IndexOf(sides[s]);
      (first ? row.num_nodes : row.num_nodes2) = 2;
      auto& nodes = first ? row.nodes : row.nodes2;
      auto& J = first ? row.J : row.J2;
      nodes[0] = 0;
      nodes[1] = 1;
      J[0] = joint_row.J[2 * s];
      J[1] = joint_row.J[2 * s + 1];
    }
  }
  return static_cast<int>(rows_.size());
}

double JointSource::CalcIslandViolationSum(const IslandIterate& iterate) const {
  double sum = 0.0;
  for (const JointRow& row : rows_) sum += CalcViolation(iterate, row);
  return sum;
}

}  // namespace taut
