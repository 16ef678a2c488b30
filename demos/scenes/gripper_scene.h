// An articulated robot gripping a deformable: a two-finger btMultiBody gripper (a prismatic lift
// joint and two prismatic finger joints, each driven by a btMultiBodyJointMotor) squeezes a soft,
// strain-limited tet cube and lifts it off the ground. The gripper's links, their motors and the
// cube's contact and strain-limit rows are solved in one island (DeformableMultiBodyWorld).
#pragma once

#include <BulletDynamics/Featherstone/btMultiBodyJointMotor.h>

#include "demos/scenes/multibody_world_holder.h"
#include "demos/scenes/scene.h"

namespace taut {

// Geometry and masses of the gripper (z up).
struct GripperSettings {
  Vec3 base = Vec3(0.0, 0.0, 0.3);                    // fixed base: the lift joint's origin [m]
  double finger_drop = 0.25;                          // finger centres below the base [m]
  double finger_offset = 0.07;                        // |x| of the finger centres at q = 0 [m]
  Vec3 finger_half_extents = Vec3(0.01, 0.03, 0.04);  // box fingers [m]
  double carriage_mass = 1.0;                         // the lift link [kg]
  double finger_mass = 0.2;                           // each finger [kg]
  double friction = 1.0;                              // of the finger colliders
};

// The gripper's multibody (fixed base; link 0 the carriage, prismatic along +z; links 1 and 2 the
// left and right fingers, prismatic along +x and -x, so q > 0 closes both) and its motors.
struct GripperRig {
  btMultiBody* body = nullptr;
  btMultiBodyJointMotor* lift = nullptr;
  btMultiBodyJointMotor* fingers[2] = {nullptr, nullptr};
};

// Builds the gripper in `world` (objects owned by `objects`), motors at rest with zero force.
GripperRig AddGripper(btMultiBodyDynamicsWorld& world, MultiBodyObjects& objects,
                      const GripperSettings& settings);
// Motor targets for a step dt: the lift at `lift_speed` [m/s] (up > 0) with at most `lift_force`
// [N], both fingers closing at `close_speed` [m/s] with at most `squeeze_force` [N] each.
void DriveGripper(const GripperRig& rig, double lift_speed, double lift_force, double close_speed,
                  double squeeze_force, double dt);

class GripperScene : public Scene {
 public:
  // The run: the fingers close (squeeze_force each) for `grip_time`, then the carriage lifts at
  // lift_speed for `lift_time`, then holds.
  struct Settings {
    double cube_side = 0.1;        // [m], 4 x 4 x 4 cells of 6 tets, resting on the ground
    double youngs_modulus = 20e3;  // [Pa]
    double density = 400.0;        // [kg/m^3]: a 0.4 kg cube
    double strain_min = 0.9;       // isotropic strain limits (paper A)
    double strain_max = 1.1;
    double friction = 1.0;        // the cube's (times the fingers' 1.0)
    double squeeze_force = 15.0;  // [N] per finger
    double close_speed = 0.2;     // [m/s]
    double lift_force = 100.0;    // [N]
    double lift_speed = 0.1;      // [m/s]
    double grip_time = 0.4;       // [s]
    double lift_time = 0.5;       // [s]
  };
  GripperScene() : GripperScene(Settings()) {}
  explicit GripperScene(const Settings& settings);

  void Simulate(double dt) override;
  void Measure(double dt) override;
  std::vector<std::string> CsvColumns() const override;
  void AppendCsvValues(std::vector<double>& values) const override;
  void WriteFigures(nlohmann::json& figures) const override;
  Vec3 GetCameraDirection() const override { return Vec3(0.3, -1.0, 0.35); }

  // The scene's own world (generic code reads it through these).
  int num_deformable_bodies() const override { return mb_.world.num_deformable_bodies(); }
  const DeformableBody& deformable_body(int b) const override {
    return mb_.world.deformable_body(b);
  }
  const btCollisionObjectArray& collision_objects() const override {
    return mb_.world.getCollisionObjectArray();
  }
  const StepStats& last_step_stats() const override { return mb_.world.last_step_stats(); }
  SqpSettings& mutable_solver_settings() override { return mb_.world.mutable_solver_settings(); }
  void SetThreadCount(int threads) override { mb_.world.SetThreadCount(threads); }

  DeformableMultiBodyWorld& multibody_world() { return mb_.world; }
  const GripperRig& rig() const { return rig_; }
  const DeformableBody& cube() const { return *cube_; }
  // The cube's centre of mass now [m].
  Vec3 CalcCubeCenterOfMass() const;
  // Height of the carriage above its start [m] (the lift joint's position).
  double lift_height() const;
  // Inner faces of the fingers along x now [m] (left, right).
  double finger_face(int f) const;
  // Lift of the cube's centre of mass since the start [m] and the carriage's lift minus it (slip).
  double com_rise() const { return CalcCubeCenterOfMass().z() - start_com_.z(); }
  double slip() const { return lift_height() - com_rise(); }
  double time() const { return time_; }

 private:
  Settings settings_;
  GripperSettings gripper_;
  MultiBodyWorldHolderOf<DeformableMultiBodyWorld> mb_;
  GripperRig rig_;
  DeformableBody* cube_ = nullptr;
  Vec3 start_com_;
  double time_ = 0.0;
  double max_slip_ = 0.0;  // during the hold after the lift
  double slip_at_lift_end_ = 0.0;
};

}  // namespace taut
