#include "demos/scenes/finger_scene.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "bullet_bridge/eigen_bullet.h"

namespace taut {

namespace {
constexpr double kLength = 0.07;            // finger length [m]
constexpr double kYoungsModulus = 2e6;      // [Pa], paper A §5.2 (nu = 0.3)
constexpr double kDensity = 1000.0;         // [kg/m^3], paper A §5.2
constexpr double kContactTolerance = 1e-5;  // a node this close to the table touches it [m]
constexpr double kContactMargin = 1e-3;     // rows for nodes this close to the table [m]
constexpr double kBoneShapeRadius = 0.002;  // collision capsule of the bone, inside the flesh [m]

// Rotation taking the finger's body frame to the world so that the pressed side faces -z.
Mat3 CalcPressRotation(FingerPressAxis axis) {
  Mat3 R;
  switch (axis) {
    case FingerPressAxis::kFlat:  // body x -> x, y (nail) -> z, z -> -y
      R << 1, 0, 0, 0, 0, -1, 0, 1, 0;
      break;
    case FingerPressAxis::kSide:  // body frame = world frame: -z side down
      R.setIdentity();
      break;
    case FingerPressAxis::kTip:  // body x (tip) -> -z, y -> y, z -> x
      R << 0, 0, 1, 0, 1, 0, -1, 0, 0;
      break;
  }
  return R;
}
}  // namespace

const char* GetFingerPressAxisName(FingerPressAxis axis) {
  switch (axis) {
    case FingerPressAxis::kFlat:
      return "flat";
    case FingerPressAxis::kSide:
      return "side";
    case FingerPressAxis::kTip:
      return "tip";
  }
  return "?";
}

FingerModel FingerScene::Anisotropic() {
  return {"anisotropic",
          StrainLimitSettings::PerAxis(Vec3(0.95, 0.75, 0.98), Vec3(1.05, 1.25, 1.02))};
}

FingerModel FingerScene::Isotropic() {
  return {"isotropic", StrainLimitSettings::Isotropic(0.75, 1.25)};
}

std::vector<FingerPress> FingerScene::DefaultPresses() {
  std::vector<FingerPress> presses;
  for (FingerPressAxis axis :
       {FingerPressAxis::kFlat, FingerPressAxis::kSide, FingerPressAxis::kTip})
    for (const FingerModel& model : {Anisotropic(), Isotropic()}) presses.push_back({axis, model});
  return presses;
}

double FingerScene::CalcPressDuration(const FingerSceneSettings& settings) {
  // Twice the time of the travel at full speed: the bone slows down near the target force.
  return 2.0 * (settings.start_gap + settings.max_indentation) / settings.bone_speed +
         settings.hold_time;
}

FingerScene::FingerScene(const std::vector<FingerPress>& presses,
                         const FingerSceneSettings& settings)
    : presses_(presses), settings_(settings) {
  TAUT_DEMAND(!presses.empty(), "finger scene: no presses");
  TAUT_DEMAND(settings.target_force > 0.0 && settings.bone_speed > 0.0 &&
                  settings.max_indentation > 0.0 && settings.start_gap >= 0.0 &&
                  settings.hold_time >= 0.0 && settings.lock_violation > 0.0 &&
                  settings.lock_penetration > 0.0 && settings.bone_radius > 0.0 &&
                  settings.solver_tolerance > 0.0 && settings.mass_damping >= 0.0,
              "finger scene: target force, bone speed, travel cap, lock thresholds, bone "
              "radius and solver tolerance must be > 0, start gap, hold time and damping >= 0");
  const std::vector<Capsule> phalanges = MakeFingerCapsules(kLength);
  auto mesh = std::make_shared<TetMesh>(MakeCapsuleUnionTetMesh(phalanges, settings.mesh));
  mesh->source = "finger";
  body_mesh_ = mesh;
  // Bone: the nodes within bone_radius of the phalanx axes.
  std::vector<Capsule> bone = phalanges;
  for (Capsule& c : bone) c.radius = settings.bone_radius;
  double x_lo = HUGE_VAL, x_hi = -HUGE_VAL;
  for (int i = 0; i < static_cast<int>(mesh->nodes.size()); ++i) {
    if (CalcCapsuleUnionDistance(bone, mesh->nodes[i]) > 0.0) continue;
    bone_nodes_.push_back(i);
    x_lo = std::min(x_lo, mesh->nodes[i].x());
    x_hi = std::max(x_hi, mesh->nodes[i].x());
  }
  TAUT_DEMAND(!bone_nodes_.empty(), "finger scene: no node within the bone radius ",
              settings.bone_radius, " m of the axis (use smaller cells)");
  boundary_faces_ = CalcBoundaryFaces(*mesh);
  boundary_nodes_ = CalcBoundaryNodes(*mesh);
  AddTableAndBone(x_hi - x_lo);
  bone_centre_ = Vec3(0.5 * (x_lo + x_hi), 0.0, 0.0);
  // The reaction is read from the solved contact impulses: limits held to 1e-5 of their range
  // (not the default 1e-3) and nearly stationary QPs keep the solver's tolerance out of it.
  world().mutable_solver_settings().violation_tolerance = settings.solver_tolerance;
  world().mutable_solver_settings().stationarity_tolerance = settings.solver_tolerance * 100.0;
  results_.resize(presses.size());
  BeginPress(0);
}

void FingerScene::AddTableAndBone(double bone_length) {
  // Static frictionless table, top face at z = 0.
  holder_.shapes.push_back(std::make_unique<btBoxShape>(btVector3(0.1, 0.1, 0.01)));
  btRigidBody::btRigidBodyConstructionInfo table(0.0, nullptr, holder_.shapes.back().get());
  table.m_startWorldTransform.setOrigin(btVector3(0.035, 0.0, -0.01));
  holder_.rigid_bodies.push_back(std::make_unique<btRigidBody>(table));
  table_ = holder_.rigid_bodies.back().get();
  table_->setFriction(0.0);
  world().addRigidBody(table_);
  // Kinematic bone: a thin capsule along the body x axis over the pinned nodes.
  holder_.shapes.push_back(
      std::make_unique<btCapsuleShapeX>(kBoneShapeRadius, std::max(bone_length, 1e-3)));
  holder_.motion_states.push_back(std::make_unique<btDefaultMotionState>());
  bone_state_ = holder_.motion_states.back().get();
  holder_.rigid_bodies.push_back(
      std::make_unique<btRigidBody>(0.0, bone_state_, holder_.shapes.back().get()));
  bone_ = holder_.rigid_bodies.back().get();
  bone_->setCollisionFlags(bone_->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
  bone_->setActivationState(DISABLE_DEACTIVATION);
  world().addRigidBody(bone_);
}

void FingerScene::BeginPress(int p) {
  current_ = p;
  const FingerPress& press = presses_[p];
  FingerPressResult& result = results_[p];
  result = FingerPressResult();
  result.name = std::string(GetFingerPressAxisName(press.axis)) + "_" + press.model.name;
  // Rotate the rest mesh so the pressed side faces the table, start_gap above it.
  rotation_ = CalcPressRotation(press.axis);
  auto mesh = std::make_shared<TetMesh>(*body_mesh_);
  mesh->source = result.name;
  double lowest = HUGE_VAL;
  for (Vec3& X : mesh->nodes) {
    X = rotation_ * X;
    lowest = std::min(lowest, X.z());
  }
  offset_ = Vec3(0.0, 0.0, settings_.start_gap - lowest);
  for (Vec3& X : mesh->nodes) X += offset_;
  DeformableBodySettings body =
      MakeSceneBodySettings(result.name, kYoungsModulus, kDensity, settings_.mass_damping);
  body.contact_margin = kContactMargin;
  finger_ = world().AddTetBody(mesh, body);
  // Limits in the body frame: the limit axes are the rotated body axes (columns of R).
  StrainLimitSettings limits = press.model.limits;
  limits.frame = rotation_;
  limits_ = world().SetStrainLimits(finger_, limits);
  time_ = held_ = travel_ = last_travel_ = contact_travel_ = reaction_ = 0.0;
  stopped_ = false;
  speed_factor_ = 1.0;
  sqp_sum_ = sweep_sum_ = ms_sum_ = 0.0;
  UpdateBoneTravel(0.0);
  world().AttachNodesToRigidBody(finger_, bone_nodes_, bone_);
  finger_->PrepareSystem();  // the symbolic analysis at set-up, not in the press's first step
}

void FingerScene::EndPress() {
  FingerPressResult& result = results_[current_];
  result.contact_area = CalcContactArea();
  result.elastic_reaction = CalcElasticReaction();
  world().RemoveDeformableBody(finger_);
  finger_ = nullptr;
  limits_ = nullptr;
  if (current_ + 1 < num_presses()) {
    BeginPress(current_ + 1);
  } else {
    current_ = num_presses();
  }
}

void FingerScene::UpdateBoneTravel(double dt) {
  // Slow down over the last 30 % of the target force (less overshoot), to 5 % of the speed, never
  // speeding up again.
  const double remaining = (settings_.target_force - reaction_) / (0.3 * settings_.target_force);
  speed_factor_ = std::min(speed_factor_, std::clamp(remaining, 0.05, 1.0));
  if (!stopped_) travel_ += speed_factor_ * settings_.bone_speed * dt;
  btTransform pose;
  pose.setBasis(btMatrix3x3(rotation_(0, 0), rotation_(0, 1), rotation_(0, 2), rotation_(1, 0),
                            rotation_(1, 1), rotation_(1, 2), rotation_(2, 0), rotation_(2, 1),
                            rotation_(2, 2)));
  pose.setOrigin(ToBullet(rotation_ * bone_centre_ + offset_ - travel_ * Vec3::UnitZ()));
  bone_state_->setWorldTransform(pose);
  bone_->setWorldTransform(pose);
}

void FingerScene::Simulate(double dt) {
  if (current_ >= num_presses()) return Scene::Simulate(dt);
  // Only an advance against the table can lock; a snapshot before it lets it be taken back.
  const bool guarded =
      settings_.take_back_locked_advances && !stopped_ && results_[current_].touched;
  if (guarded) world().SaveSnapshot(advance_start_);  // in place: no allocation per step
  UpdateBoneTravel(dt);
  Scene::Simulate(dt);
  if (guarded && !world().last_step_stats().converged) RetreatFromLockedAdvance(dt);
}

void FingerScene::RetreatFromLockedAdvance(double dt) {
  locked_x_ = finger_->x();
  retreated_ = true;
  world().RestoreSnapshot(advance_start_);
  travel_ = last_travel_;
  stopped_ = true;
  UpdateBoneTravel(0.0);
  Scene::Simulate(dt);
}

void FingerScene::Measure(double dt) {
  if (current_ >= num_presses()) return;
  MeasureStep();
  time_ += dt;
  if (stopped_) held_ += dt;
  if (held_ >= settings_.hold_time - 1e-9 || time_ >= CalcPressDuration(settings_) - 1e-9)
    EndPress();
}

double FingerScene::CalcTableReaction() const {
  // R = sum over the finger's contacts with the table of f_c . z, f_c = impulse / h on the finger.
  double reaction = 0.0;
  for (const DeformableContactPoint& contact : world().last_substep_forces().contacts)
    if (contact.body == finger_ && contact.partner_object == table_) reaction += contact.force.z();
  return reaction;
}

double FingerScene::CalcFreeWeight() const {
  double mass = 0.0;
  for (int i = 0; i < finger_->num_nodes(); ++i)
    if (finger_->node_kind(i) == NodeKind::kFree) mass += finger_->mass()[i];
  return -mass * world().getGravity().z();
}

double FingerScene::CalcElasticReaction() const {
  // Static balance of the free nodes: R = sum_bone f_e,z + W_free (internal forces sum to zero).
  // The element rotations this refreshes at x are the ones the next step starts from anyway.
  scratch_.setZero(3 * finger_->num_nodes());
  finger_->mutable_model().UpdateRotationsAndAddForces(finger_->x(), scratch_);
  double force = CalcFreeWeight();
  for (int i : bone_nodes_) force += scratch_[3 * i + 2];
  return force;
}

double FingerScene::CalcLowestGap(const VecX& x) const {
  double lowest = HUGE_VAL;
  for (int i : boundary_nodes_) lowest = std::min(lowest, x[3 * i + 2]);
  return lowest;
}

double FingerScene::CalcContactArea() const {
  // A third of every boundary triangle's deformed area goes to each of its nodes.
  double area = 0.0;
  for (const Triangle& t : boundary_faces_) {
    const Vec3 a = finger_->node_position(t[0]), b = finger_->node_position(t[1]),
               c = finger_->node_position(t[2]);
    const double share = (b - a).cross(c - a).norm() / 6.0;
    for (const Vec3& p : {a, b, c})
      if (p.z() <= kContactTolerance) area += share;
  }
  return area;
}

void FingerScene::MeasureStep() {
  FingerPressResult& result = results_[current_];
  const StepStats& stats = world().last_step_stats();
  ++result.steps;
  result.max_sqp_iterations = std::max(result.max_sqp_iterations, stats.sqp_iterations);
  sqp_sum_ += stats.sqp_iterations;
  sweep_sum_ += stats.pgs_sweeps;
  ms_sum_ += stats.ms_total;
  result.mean_sqp_iterations = sqp_sum_ / result.steps;
  result.mean_pgs_sweeps = sweep_sum_ / result.steps;
  result.mean_ms_step = ms_sum_ / result.steps;
  const double gap = CalcLowestGap(finger_->x());
  const double violation = limits_->CalcMaxViolation(finger_->x());
  if (retreated_) {
    // The advance taken back before this step was stepped again at the last travel.
    retreated_ = false;
    result.lock_violation = limits_->CalcMaxViolation(locked_x_);
    result.lock_penetration = -CalcLowestGap(locked_x_);
    result.stop_reason = "lock";
    result.indentation = std::max(0.0, travel_ - contact_travel_);
  }
  const bool lock =
      !stopped_ && (violation > settings_.lock_violation || -gap > settings_.lock_penetration);
  if (lock) {
    // The rejected advance: how far it broke the limits and the contact.
    result.lock_violation = violation;
    result.lock_penetration = -gap;
  } else {
    result.max_violation = std::max(result.max_violation, violation);
    result.max_penetration = std::max(result.max_penetration, -gap);
  }
  if (stopped_) return;
  if (lock) {
    // Locked: the last advance could not be followed; step back to the last feasible travel.
    travel_ = last_travel_;
    stopped_ = true;
    result.stop_reason = "lock";
  } else if (!result.touched && gap > kContactTolerance) {
    // Before contact the finger hangs on the bone and moves with it: contact at travel + gap.
    contact_travel_ = travel_ + gap;
  } else {
    result.touched = true;
    reaction_ = CalcTableReaction();
    if (reaction_ >= settings_.target_force) {
      stopped_ = true;
      result.stop_reason = "force";
    } else if (travel_ - contact_travel_ >= settings_.max_indentation) {
      stopped_ = true;
      result.stop_reason = "travel";
    }
  }
  if (result.stop_reason != "lock") last_travel_ = travel_;
  result.indentation = std::max(0.0, travel_ - contact_travel_);
  result.reaction = reaction_;
}

std::vector<std::string> FingerScene::CsvColumns() const {
  return {"press",           "bone_travel_m", "indentation_m",   "reaction_N", "elastic_reaction_N",
          "contact_area_m2", "lowest_gap_m",  "strain_violation"};
}

void FingerScene::AppendCsvValues(std::vector<double>& values) const {
  if (finger_ == nullptr) {
    values.insert(values.end(), {static_cast<double>(current_), 0, 0, 0, 0, 0, 0, 0});
    return;
  }
  values.push_back(current_);
  values.push_back(travel_);
  values.push_back(std::max(0.0, travel_ - contact_travel_));
  values.push_back(reaction_);
  values.push_back(CalcElasticReaction());
  values.push_back(CalcContactArea());
  values.push_back(CalcLowestGap(finger_->x()));
  values.push_back(limits_->CalcMaxViolation(finger_->x()));
}

void FingerScene::WriteFigures(nlohmann::json& figures) const {
  figures["num_tets"] = body_mesh_->tets.size();
  figures["num_bone_nodes"] = bone_nodes_.size();
  figures["target_force_N"] = settings_.target_force;
  figures["bone_speed_m_per_s"] = settings_.bone_speed;
  for (int p = 0; p < num_presses() && p <= current_; ++p) {
    const FingerPressResult& r = results_[p];
    nlohmann::json& entry = figures["presses"][r.name];
    entry["done"] = p < current_;
    entry["touched"] = r.touched;
    entry["indentation_m"] = r.indentation;
    entry["reaction_N"] = r.reaction;
    entry["elastic_reaction_N"] = r.elastic_reaction;
    entry["stop_reason"] = r.stop_reason;
    entry["contact_area_m2"] = r.contact_area;
    entry["max_strain_violation"] = r.max_violation;
    entry["max_penetration_m"] = r.max_penetration;
    entry["lock_violation"] = r.lock_violation;
    entry["lock_penetration_m"] = r.lock_penetration;
    entry["steps"] = r.steps;
    entry["max_sqp_iterations"] = r.max_sqp_iterations;
    entry["mean_sqp_iterations"] = r.mean_sqp_iterations;
    entry["mean_pgs_sweeps"] = r.mean_pgs_sweeps;
    entry["mean_ms_step"] = r.mean_ms_step;
  }
  // Anisotropic over isotropic indentation per axis (the contact geometry cancels).
  for (int p = 0; p < num_presses() && p < current_; ++p)
    for (int q = 0; q < num_presses() && q < current_; ++q)
      if (presses_[p].axis == presses_[q].axis && presses_[p].model.name == "anisotropic" &&
          presses_[q].model.name == "isotropic" && results_[q].indentation > 0.0)
        figures["indentation_ratio_anisotropic_to_isotropic"]
               [GetFingerPressAxisName(presses_[p].axis)] =
                   results_[p].indentation / results_[q].indentation;
}

std::vector<Scene::KeyFrame> FingerScene::CollectKeyFrames(int step, int /*num_steps*/) {
  // The bone stops (force reached, locked or travel cap) and holds: the press at its deepest.
  if (step == 0 || current_ >= num_presses() || !stopped_ || key_press_ >= current_) return {};
  key_press_ = current_;
  const FingerPressResult& r = results_[current_];
  char caption[160];
  std::snprintf(caption, sizeof(caption), "%s: %.1f N, %.2f mm (%s)", r.name.c_str(), r.reaction,
                1e3 * r.indentation, r.stop_reason.c_str());
  return {{"press_" + r.name, caption}};
}

}  // namespace taut
