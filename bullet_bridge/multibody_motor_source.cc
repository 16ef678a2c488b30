#include "bullet_bridge/multibody_motor_source.h"

#include <algorithm>

namespace taut {

namespace {
// Bullet keeps a motor's targets and gains protected; a derived type's pointers to those members
// read them from any motor (they are members of btMultiBodyJointMotor).
struct MotorFields : btMultiBodyJointMotor {
  static constexpr btScalar btMultiBodyJointMotor::*kDesiredVelocity =
      &MotorFields::m_desiredVelocity;
  static constexpr btScalar btMultiBodyJointMotor::*kDesiredPosition =
      &MotorFields::m_desiredPosition;
  static constexpr btScalar btMultiBodyJointMotor::*kKd = &MotorFields::m_kd;
  static constexpr btScalar btMultiBodyJointMotor::*kKp = &MotorFields::m_kp;
  static constexpr btScalar btMultiBodyJointMotor::*kErp = &MotorFields::m_erp;
  static constexpr btScalar btMultiBodyJointMotor::*kRhsClamp = &MotorFields::m_rhsClamp;
};
}  // namespace

void MultiBodyMotorSource::AddMotor(const btMultiBodyJointMotor& motor,
                                    const MultiBodyIslandBody* body, int motor_id) {
  TAUT_DEMAND(body != nullptr, "multibody motor ", motor_id, ": island body is null");
  const btMultiBody& multibody = *body->multibody();
  const int link = motor.getLinkA();
  TAUT_DEMAND(link >= 0 && link < multibody.getNumLinks(), "multibody motor ", motor_id, ": link ",
              link, " out of range [0, ", multibody.getNumLinks(), ")");
  TAUT_DEMAND(
      multibody.getLink(link).m_dofCount == 1, "multibody motor ", motor_id, ": link ", link,
      " has ", multibody.getLink(link).m_dofCount,
      " dofs; only prismatic and revolute joints (1 dof) have motors in a deformable island");
  motors_.push_back({&motor, body, 6 + multibody.getLink(link).m_dofOffset, motor_id});
}

double MultiBodyMotorSource::CalcTargetRate(const Motor& motor, double h) const {
  const btMultiBodyJointMotor& m = *motor.motor;
  const double q = static_cast<double>(motor.body->multibody()->getJointPos(m.getLinkA()));
  const double rate_star = motor.body->v_star()[motor.velocity_index];
  const double kp = m.*MotorFields::kKp, kd = m.*MotorFields::kKd;
  const double erp = m.*MotorFields::kErp, clamp = m.*MotorFields::kRhsClamp;
  const double position_term = erp * (m.*MotorFields::kDesiredPosition - q) / h;
  const double r =
      kp * position_term + rate_star + kd * (m.*MotorFields::kDesiredVelocity - rate_star);
  return std::clamp(r, -clamp, clamp);
}

int MultiBodyMotorSource::AppendIslandRows(const IslandIterate& iterate,
                                           std::vector<ConstraintRow>& rows) {
  for (const Motor& motor : motors_) {
    const int b = iterate.IndexOf(motor.body);
    const double p_max = static_cast<double>(motor.motor->getMaxAppliedImpulse());
    ConstraintRow& row = rows.emplace_back();
    row.key = key_.Pack(motor.motor_id, 0);
    row.type = RowType::kJoint;
    row.bilateral = true;
    row.lo = -p_max;
    row.hi = p_max;
    row.body = b;
    row.num_nodes = 1;
    row.nodes[0] = motor.velocity_index / 3;
    row.J[0] = Vec3::Unit(motor.velocity_index % 3);
    const double rate = iterate.v(b)[motor.velocity_index];
    row.C = iterate.h() * (rate - CalcTargetRate(motor, iterate.h()));
  }
  return static_cast<int>(motors_.size());
}

}  // namespace taut
