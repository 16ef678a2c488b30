#include "demos/scenes/gripper_scene.h"

#include "bullet_bridge/eigen_bullet.h"
#include "constraints/strain_limits.h"
#include "plugin/box_tet_mesher.h"

namespace taut {

namespace {
// Inertia of a solid box of `mass` with half extents `half` about its centre (diagonal).
btVector3 CalcBoxInertia(double mass, const Vec3& half) {
  const Vec3 size = 2.0 * half;
  const double k = mass / 12.0;
  return ToBullet(Vec3(k * (size.y() * size.y() + size.z() * size.z()),
                       k * (size.x() * size.x() + size.z() * size.z()),
                       k * (size.x() * size.x() + size.y() * size.y())));
}

// A motor on 1-dof link `link`, at rest with zero force, owned by `objects`.
btMultiBodyJointMotor* AddMotor(btMultiBodyDynamicsWorld& world, MultiBodyObjects& objects,
                                btMultiBody* body, int link) {
  auto motor = std::make_unique<btMultiBodyJointMotor>(body, link, btScalar(0), btScalar(0));
  btMultiBodyJointMotor* added = motor.get();
  objects.constraints.push_back(std::move(motor));
  world.addMultiBodyConstraint(added);
  return added;
}
}  // namespace

GripperRig AddGripper(btMultiBodyDynamicsWorld& world, MultiBodyObjects& objects,
                      const GripperSettings& settings) {
  objects.multibodies.push_back(
      std::make_unique<btMultiBody>(3, btScalar(1), btVector3(1, 1, 1), true, false));
  btMultiBody* body = objects.multibodies.back().get();
  body->setBasePos(ToBullet(settings.base));
  body->setWorldToBaseRot(btQuaternion::getIdentity());
  const btQuaternion identity = btQuaternion::getIdentity();
  const btVector3 zero(0, 0, 0);
  const Vec3 carriage_half(0.02, 0.02, 0.02);
  body->setupPrismatic(0, static_cast<btScalar>(settings.carriage_mass),
                       CalcBoxInertia(settings.carriage_mass, carriage_half), -1, identity,
                       btVector3(0, 0, 1), zero, zero, true);
  const Vec3& half = settings.finger_half_extents;
  for (int f = 0; f < 2; ++f) {
    const double side = f == 0 ? -1.0 : 1.0;  // left finger at -x closes along +x
    const btVector3 pivot(static_cast<btScalar>(side * settings.finger_offset), 0,
                          static_cast<btScalar>(-settings.finger_drop));
    body->setupPrismatic(1 + f, static_cast<btScalar>(settings.finger_mass),
                         CalcBoxInertia(settings.finger_mass, half), 0, identity,
                         btVector3(static_cast<btScalar>(-side), 0, 0), pivot, zero, true);
  }
  body->finalizeMultiDof();
  body->setCanSleep(false);
  world.addMultiBody(body);
  // Every link gets a collider: Bullet's multibody solver skips the motor of a link without one
  // (its constraint has no simulation island).
  AddLinkCollider(world, objects, body, 0, std::make_unique<btBoxShape>(ToBullet(carriage_half)),
                  settings.friction);
  for (int f = 0; f < 2; ++f)
    AddLinkCollider(world, objects, body, 1 + f, std::make_unique<btBoxShape>(ToBullet(half)),
                    settings.friction);
  GripperRig rig;
  rig.body = body;
  rig.lift = AddMotor(world, objects, body, 0);
  for (int f = 0; f < 2; ++f) rig.fingers[f] = AddMotor(world, objects, body, 1 + f);
  return rig;
}

void DriveGripper(const GripperRig& rig, double lift_speed, double lift_force, double close_speed,
                  double squeeze_force, double dt) {
  // Bullet's motor bounds the impulse per step: force times the step.
  rig.lift->setVelocityTarget(static_cast<btScalar>(lift_speed));
  rig.lift->setMaxAppliedImpulse(static_cast<btScalar>(lift_force * dt));
  for (btMultiBodyJointMotor* finger : rig.fingers) {
    finger->setVelocityTarget(static_cast<btScalar>(close_speed));
    finger->setMaxAppliedImpulse(static_cast<btScalar>(squeeze_force * dt));
  }
}

GripperScene::GripperScene(const Settings& settings) : settings_(settings) {
  AddGroundPlane(mb_.world, mb_.objects, 1.0);
  const double a = settings.cube_side;
  DeformableBodySettings body =
      MakeSceneBodySettings("cube", settings.youngs_modulus, settings.density);
  body.friction = settings.friction;
  cube_ = mb_.world.AddTetBody(MakeBoxTetMesh(Vec3::Constant(a), 4, 4, 4, Vec3(-a / 2, -a / 2, 0)),
                               body);
  mb_.world.SetStrainLimits(
      cube_, StrainLimitSettings::Isotropic(settings.strain_min, settings.strain_max));
  gripper_.finger_drop = gripper_.base.z() - a / 2;  // finger centres at the cube's mid-height
  gripper_.finger_offset = a / 2 + gripper_.finger_half_extents.x() + 0.01;  // 1 cm gaps
  rig_ = AddGripper(mb_.world, mb_.objects, gripper_);
  start_com_ = CalcCubeCenterOfMass();
}

void GripperScene::Simulate(double dt) {
  const Settings& s = settings_;
  const bool lifting = time_ >= s.grip_time && time_ < s.grip_time + s.lift_time;
  DriveGripper(rig_, lifting ? s.lift_speed : 0.0, s.lift_force, s.close_speed, s.squeeze_force,
               dt);
  mb_.world.stepSimulation(static_cast<btScalar>(dt), 1, static_cast<btScalar>(dt));
  time_ += dt;
}

void GripperScene::Measure(double /*dt*/) {
  if (time_ < settings_.grip_time + settings_.lift_time) {
    slip_at_lift_end_ = slip();
    return;
  }
  max_slip_ = std::max(max_slip_, std::abs(slip() - slip_at_lift_end_));
}

Vec3 GripperScene::CalcCubeCenterOfMass() const {
  Vec3 sum = Vec3::Zero();
  for (int i = 0; i < cube_->num_nodes(); ++i) sum += cube_->node_mass(i) * cube_->node_position(i);
  return sum / cube_->mass().sum();
}

double GripperScene::lift_height() const { return static_cast<double>(rig_.body->getJointPos(0)); }

double GripperScene::finger_face(int f) const {
  const double side = f == 0 ? -1.0 : 1.0;
  const double centre = side * (gripper_.finger_offset - rig_.body->getJointPos(1 + f));
  return centre - side * gripper_.finger_half_extents.x();
}

std::vector<std::string> GripperScene::CsvColumns() const {
  return {"lift_height_m", "cube_com_z_m", "slip_m", "finger_gap_m"};
}

void GripperScene::AppendCsvValues(std::vector<double>& values) const {
  values.push_back(lift_height());
  values.push_back(CalcCubeCenterOfMass().z());
  values.push_back(slip());
  values.push_back(finger_face(1) - finger_face(0));
}

void GripperScene::WriteFigures(nlohmann::json& figures) const {
  const Vec3 com = CalcCubeCenterOfMass();
  figures["lift_height_m"] = lift_height();
  figures["cube_com_rise_m"] = com_rise();
  figures["slip_m"] = slip();
  figures["slip_during_hold_m"] = max_slip_;
  figures["cube_com_x_m"] = com.x();
  figures["cube_between_fingers"] = com.x() > finger_face(0) && com.x() < finger_face(1);
  figures["finger_gap_m"] = finger_face(1) - finger_face(0);
}

}  // namespace taut
