// Paper A Fig. 3 (§5.2): a 7 cm finger (three capsule phalanges, 378 tets, density 1000 kg/m^3,
// E = 2 MPa) is pressed by a kinematic bone onto a static table flat (pad down), on its side and on
// its tip, with anisotropic limits (0.95..1.05 along the finger, 0.75..1.25 along the nail normal,
// 0.98..1.02 across, body frame, hyperbolic projection) and with isotropic 0.75..1.25.
#pragma once

#include <string>
#include <vector>

#include "bullet_bridge/world_snapshot.h"
#include "demos/scenes/scene.h"
#include "plugin/finger_mesher.h"

namespace taut {

// Which side of the finger meets the table. Body frame: x along the finger (tip at +x), y the nail
// normal, z across.
enum class FingerPressAxis {
  kFlat,  // body y vertical, pad (-y) on the table: the compliant axis
  kSide,  // body z vertical, -z side on the table
  kTip,   // body x vertical, tip (+x) on the table
};

// Name of a press axis for figures ("flat", "side", "tip").
const char* GetFingerPressAxisName(FingerPressAxis axis);

// A finger material: name and strain limits in the finger's body frame (frame is set per press).
struct FingerModel {
  std::string name;
  StrainLimitSettings limits;
};

// One press: the side that meets the table and the material.
struct FingerPress {
  FingerPressAxis axis;
  FingerModel model;
};

// Settings of FingerScene.
struct FingerSceneSettings {
  double target_force = 40.0;      // table reaction that stops the bone [N], > 0
  double bone_speed = 0.02;        // bone speed while pressing [m/s], > 0
  double start_gap = 2e-4;         // lowest node above the table at the start [m], >= 0
  double max_indentation = 2e-3;   // travel cap after the first contact [m], > 0
  double hold_time = 0.02;         // time the bone holds still before the next press [s], >= 0
  double lock_violation = 1e-3;    // strain violation max(0, -C) that counts as locked, > 0
  double lock_penetration = 5e-6;  // penetration that counts as locked [m], > 0
  double bone_radius = 0.005;      // nodes this close to the phalanx axis are pinned [m], > 0
  double mass_damping = 2.0;       // Rayleigh alpha [1/s]
  // SQP violation tolerance of the limit rows (C fraction), > 0; stationarity 100 times it.
  double solver_tolerance = 1e-5;
  // An advance after the first contact whose step is not certified is taken back from a snapshot
  // and stepped again at the last travel (false: kept, and judged by the lock thresholds alone).
  bool take_back_locked_advances = true;
  CapsuleMeshSettings mesh;  // 7 x 3 x 3 cells -> 378 tets
};

// What one press of FingerScene did.
struct FingerPressResult {
  std::string name;          // "<axis>_<model>", e.g. "flat_anisotropic"
  bool touched = false;      // the finger reached the table
  double indentation = 0.0;  // bone travel after the first contact when it stopped [m]
  double reaction = 0.0;     // table reaction when the bone stopped [N]
  // At the end of the hold, the part of the reaction the elastic forces at the bone nodes carry
  // (all of it when no limit row of an element at the bone is active): the elements' forces on
  // the bone nodes plus the free nodes' weight [N].
  double elastic_reaction = 0.0;
  std::string stop_reason;       // "force", "lock", "travel" or "" (still pressing)
  double contact_area = 0.0;     // area of the nodes in contact at the end of the hold [m^2]
  double max_violation = 0.0;    // largest strain-limit max(0, -C) over the accepted steps
  double max_penetration = 0.0;  // deepest node below the table top over the accepted steps [m]
  double lock_violation = 0.0;   // the same at the rejected advance that detected a lock
  double lock_penetration = 0.0;
  int steps = 0;
  int max_sqp_iterations = 0;
  double mean_sqp_iterations = 0.0;
  double mean_pgs_sweeps = 0.0;
  double mean_ms_step = 0.0;  // world step time [ms]
};

// The presses run one after another in the same world (one finger at a time, sides compared at
// the same force). Why force control: with hard limits the tissue between bone and table locks
// once its strain along the press reaches the limit, and a prescribed bone travel beyond that
// cannot be followed (the QP turns infeasible), so equal travels would not compare compliance.
// Each press: the bone (pinned to the inner nodes) moves down at bone_speed, slowing near the
// target, until the table reaction reaches target_force ("force"), the tissue locks ("lock": an
// advance whose constrained step cannot be certified, or that breaks a limit or the contact beyond
// the lock thresholds; the world goes back to the step's start, from a snapshot, and the step is
// taken again with the bone at the last travel that held, so the locked advance is never kept, and
// the reaction is the one it locked at), or the travel cap ("travel"); then it holds still for
// hold_time. The table reaction is read from the step's contact forces:
// the z components of the table's forces on the finger, R = sum_c lambda_n,c n_c . z / h (the
// solved impulses, DeformableWorld::last_contacts; the table is frictionless). Indentation = bone
// travel after the first contact: the table does not move and nothing sinks into it, so the tissue
// between bone and table is compressed by that much.
class FingerScene : public Scene {
 public:
  explicit FingerScene(const std::vector<FingerPress>& presses,
                       const FingerSceneSettings& settings = FingerSceneSettings());
  // Paper A: 0.95..1.05 on x, 0.75..1.25 on y, 0.98..1.02 on z, hyperbolic projection.
  static FingerModel Anisotropic();
  // Paper A's comparison: 0.75..1.25 on every axis.
  static FingerModel Isotropic();
  // Flat, side and tip, each with Anisotropic() then Isotropic().
  static std::vector<FingerPress> DefaultPresses();
  // Longest simulated time one press may take with these settings [s].
  static double CalcPressDuration(const FingerSceneSettings& settings);

  // Moves the bone (UpdateBoneTravel) and steps the world; an advance after the first contact
  // that cannot be followed is taken back (RetreatFromLockedAdvance).
  void Simulate(double dt) override;
  // MeasureStep, then the press's clock; ends the press when its hold or duration is over.
  void Measure(double dt) override;
  std::vector<std::string> CsvColumns() const override;
  void AppendCsvValues(std::vector<double>& values) const override;
  void WriteFigures(nlohmann::json& figures) const override;
  // Pictures: each press when the bone stops (its largest indentation).
  std::vector<KeyFrame> CollectKeyFrames(int step, int num_steps) override;

  int num_presses() const { return static_cast<int>(presses_.size()); }
  // Index of the press running now (num_presses() once all are done).
  int current_press() const { return current_; }
  const FingerPressResult& result(int p) const { return results_[p]; }
  // Tet mesh of the finger in its body frame.
  const TetMesh& body_mesh() const { return *body_mesh_; }
  // Nodes pinned to the bone.
  const std::vector<int>& bone_nodes() const { return bone_nodes_; }
  // The kinematic bone, the static table and the current press's finger (null between presses).
  btRigidBody* bone() const { return bone_; }
  btRigidBody* table() const { return table_; }
  DeformableBody* finger() const { return finger_; }

 private:
  // Adds the static frictionless table (top at z = 0) and the kinematic bone, a thin capsule of
  // the given length along the body x axis.
  void AddTableAndBone(double bone_length);
  // Adds press p's finger (rotated onto its axis), limits and bone attachment.
  void BeginPress(int p);
  // Removes the current finger and moves on.
  void EndPress();
  // Picks the bone travel of the next step (press, stop or step back).
  void UpdateBoneTravel(double dt);
  // The advance just stepped locked (its step is not certified): keeps its positions for
  // MeasureStep, restores the world to the step's start and steps again at the last travel.
  void RetreatFromLockedAdvance(double dt);
  // Records the step just taken into the current result and stop state.
  void MeasureStep();
  // Table reaction of the last step: the z force of the table's contacts on the finger [N].
  double CalcTableReaction() const;
  // Area of the boundary nodes within contact tolerance of the table [m^2].
  double CalcContactArea() const;
  // Weight of the free nodes [N].
  double CalcFreeWeight() const;
  // Elastic part of the table reaction (FingerPressResult::elastic_reaction) [N].
  double CalcElasticReaction() const;
  // Lowest node height above the table at node positions x (3N) [m].
  double CalcLowestGap(const VecX& x) const;

  std::vector<FingerPress> presses_;
  FingerSceneSettings settings_;
  std::shared_ptr<const TetMesh> body_mesh_;
  std::vector<int> bone_nodes_;
  std::vector<Triangle> boundary_faces_;
  std::vector<int> boundary_nodes_;
  Vec3 bone_centre_;  // bone capsule centre in the body frame [m]
  btRigidBody* table_ = nullptr;
  btRigidBody* bone_ = nullptr;
  btDefaultMotionState* bone_state_ = nullptr;
  std::vector<FingerPressResult> results_;
  // State of the current press.
  int current_ = -1;
  DeformableBody* finger_ = nullptr;
  StrainLimitSource* limits_ = nullptr;
  Mat3 rotation_ = Mat3::Identity();  // body frame -> world
  Vec3 offset_ = Vec3::Zero();        // body origin in the world at zero travel [m]
  double time_ = 0.0;                 // time since the press began [s]
  double held_ = 0.0;                 // time since the bone stopped [s]
  double last_travel_ = 0.0;          // travel of the last step that held every limit [m]
  double travel_ = 0.0;               // bone travel downwards [m]
  double contact_travel_ = 0.0;       // travel at the first contact [m]
  bool stopped_ = false;
  WorldSnapshot advance_start_;  // the world before the advance being stepped
  bool retreated_ = false;       // this step's advance was taken back
  VecX locked_x_;                // node positions the taken-back advance reached (3N) [m]
  double speed_factor_ = 1.0;    // fraction of bone_speed (slows down near the target)
  double reaction_ = 0.0;        // table reaction of the last accepted step [N]
  mutable VecX scratch_;         // elastic forces (3N)
  double sqp_sum_ = 0.0, sweep_sum_ = 0.0, ms_sum_ = 0.0;
  int key_press_ = -1;  // last press shown in a key frame
};

}  // namespace taut
