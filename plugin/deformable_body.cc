#include "plugin/deformable_body.h"

#include <algorithm>
#include <cmath>

namespace taut {
namespace {

// Index of the first node whose 3 entries of the 3N vector v are not all finite; -1 if none.
int FindNonFiniteNode(const VecX& v) {
  for (Eigen::Index i = 0; 3 * i < v.size(); ++i)
    if (!v.segment<3>(3 * i).allFinite()) return static_cast<int>(i);
  return -1;
}

}  // namespace

DeformableBody::DeformableBody(std::unique_ptr<ElementModel> model,
                               const DeformableBodySettings& settings)
    : model_(std::move(model)), settings_(settings) {
  TAUT_DEMAND(model_ != nullptr, "body '", settings.name, "': element model is null");
  settings_.Validate();
  const int n = model_->num_nodes();
  x_ = model_->rest_positions();
  v_.setZero(3 * n);
  x0_ = x_;
  v0_ = v_;
  v_star_ = v_;
  force_.setZero(3 * n);
  external_.setZero(3 * n);
  kinematic_v_.setZero(3 * n);
  scratch_.setZero(3 * n);
  model_->CalcLumpedMass(settings_.material.density, mass_);
  kinds_.assign(n, NodeKind::kFree);
  kinematic_targets_.assign(n, Vec3::Zero());
  for (int i = 0; i < n; ++i)
    TAUT_DEMAND(mass_[i] > 0.0, "body '", name(), "': node ", i,
                " belongs to no element (zero mass); remove unused nodes from the mesh");
}

void DeformableBody::set_x(const VecX& x) {
  TAUT_DEMAND(x.size() == x_.size(), "body '", name(), "': set_x expects ", x_.size(),
              " values, got ", x.size());
  TAUT_DEMAND(x.allFinite(), "body '", name(), "': set_x got a non-finite position");
  x_ = x;
}

void DeformableBody::set_v(const VecX& v) {
  TAUT_DEMAND(v.size() == v_.size(), "body '", name(), "': set_v expects ", v_.size(),
              " values, got ", v.size());
  TAUT_DEMAND(v.allFinite(), "body '", name(), "': set_v got a non-finite velocity");
  v_ = v;
}

void DeformableBody::CheckNode(int node, const char* what) const {
  TAUT_DEMAND(node >= 0 && node < num_nodes(), "body '", name(), "': ", what, " node ", node,
              " out of range [0, ", num_nodes(), ")");
}

Vec3 DeformableBody::node_position(int i) const {
  CheckNode(i, "node_position:");
  return x_.segment<3>(3 * i);
}

Vec3 DeformableBody::node_velocity(int i) const {
  CheckNode(i, "node_velocity:");
  return v_.segment<3>(3 * i);
}

double DeformableBody::node_mass(int i) const {
  CheckNode(i, "node_mass:");
  return mass_[i];
}

Vec3 DeformableBody::node_external_force(int i) const {
  CheckNode(i, "node_external_force:");
  return external_.segment<3>(3 * i);
}

void DeformableBody::FixNodes(const std::vector<int>& nodes) {
  for (int i : nodes) {
    CheckNode(i, "FixNodes:");
    kinds_[i] = NodeKind::kFixed;
  }
  kinds_changed_ = true;
}

int DeformableBody::FixNodesWhere(const std::function<bool(const Vec3&)>& pred) {
  std::vector<int> nodes;
  for (int i = 0; i < num_nodes(); ++i)
    if (pred(model_->rest_positions().segment<3>(3 * i))) nodes.push_back(i);
  FixNodes(nodes);
  return static_cast<int>(nodes.size());
}

void DeformableBody::SetKinematicTarget(int node, const Vec3& target) {
  CheckNode(node, "SetKinematicTarget:");
  TAUT_DEMAND(target.allFinite(), "body '", name(), "': kinematic target of node ", node,
              " is not finite");
  if (kinds_[node] != NodeKind::kKinematic) kinds_changed_ = true;
  kinds_[node] = NodeKind::kKinematic;
  kinematic_targets_[node] = target;
}

void DeformableBody::ReleaseNode(int node) {
  CheckNode(node, "ReleaseNode:");
  if (kinds_[node] != NodeKind::kFree) kinds_changed_ = true;
  kinds_[node] = NodeKind::kFree;
}

void DeformableBody::AddNodeForce(int node, const Vec3& force) {
  CheckNode(node, "AddNodeForce:");
  TAUT_DEMAND(force.allFinite(), "body '", name(), "': force on node ", node, " is not finite");
  external_.segment<3>(3 * node) += force;
}

void DeformableBody::PrepareSystem() {
  if (!kinds_changed_) return;
  system_.Build(*model_, kinds_);
  kinds_changed_ = false;
}

void DeformableBody::BeginStep(double h, const Vec3& gravity) {
  TAUT_DEMAND(std::isfinite(h) && h > 0.0, "body '", name(),
              "': time step must be finite and > 0 s, got ", h);
  TAUT_DEMAND(gravity.allFinite(), "body '", name(), "': gravity must be finite, got (",
              gravity.transpose(), ")");
  PrepareSystem();
  x0_ = x_;
  v0_ = v_;
  // Forces at x0: external + elastic (updates rotations), checked, then + gravity.
  force_ = external_;
  model_->UpdateRotationsAndAddForces(x0_, force_);
  CheckForces();
  for (int i = 0; i < num_nodes(); ++i) force_.segment<3>(3 * i) += mass_[i] * gravity;
  // Prescribed velocities: fixed nodes 0, kinematic nodes reach their target at the step end.
  kinematic_v_.setZero();
  bool any_kinematic = false;
  for (int i = 0; i < num_nodes(); ++i)
    if (kinds_[i] == NodeKind::kKinematic) {
      kinematic_v_.segment<3>(3 * i) = (kinematic_targets_[i] - x0_.segment<3>(3 * i)) / h;
      any_kinematic = true;
    }
  // A = (1 + h alpha) M + (h beta + h^2) K;  b = M v0 + h f(x0) - (h beta + h^2) K v_kin.
  const double c_M = 1.0 + h * settings_.mass_damping;
  const double c_K = h * settings_.stiffness_damping + h * h;
  system_.Assemble(*model_, mass_, c_M, c_K);
  for (int i = 0; i < num_nodes(); ++i)
    v_star_.segment<3>(3 * i) = mass_[i] * v0_.segment<3>(3 * i) + h * force_.segment<3>(3 * i);
  if (any_kinematic) {  // K v_kin = 0 without kinematic nodes: one element pass saved
    scratch_.setZero();
    model_->AddScaledStiffnessTimes(c_K, kinematic_v_, scratch_);
    v_star_ -= scratch_;
  }
  try {
    last_pcg_iterations_ = system_.SolveStep(v_star_, name(), settings_.factor_reuse);
  } catch (const SimulationError&) {
    external_.setZero();  // x, v are still the step start's
    throw;
  }
  v_star_ += kinematic_v_;
  v_ = v_star_;
  CheckVelocities("unconstrained solve");
  external_.setZero();
}

void DeformableBody::SolveSystem(Eigen::Ref<VecX> rhs) {
  system_.EnsureCurrentFactor(name());
  system_.Solve(rhs);
}

void DeformableBody::SolveSystemColumns(Eigen::Ref<MatX> rhs) {
  system_.EnsureCurrentFactor(name());
  system_.SolveColumns(rhs);
}

void DeformableBody::HalfSolveSystemColumns(const SparseColumns& rhs, MatX& z) {
  system_.EnsureCurrentFactor(name());
  system_.HalfSolveColumns(rhs, z);
}

void DeformableBody::EndStep(double h) {
  CheckVelocities("end of step");
  x_ = x0_ + h * v_;
  if (!x_.allFinite())
    FailStep(internal::Concat("non-finite position x0 + h v at node ", FindNonFiniteNode(x_)),
             "end of step");
}

void DeformableBody::CheckForces() {
  if (force_.allFinite()) return;
  const int node = FindNonFiniteNode(force_);
  if (!external_.segment<3>(3 * node).allFinite())
    FailStep(internal::Concat("external force on node ", node,
                              " is not finite (the AddNodeForce calls of this step overflow)"),
             "force assembly");
  // One element with a non-finite force makes all of its nodes non-finite: name the first such
  // element, else the first element at the node.
  const int k = model_->nodes_per_element();
  auto bad = [this](int n) { return !force_.segment<3>(3 * n).allFinite(); };
  int element = -1;
  for (int e = 0; e < model_->num_elements() && element < 0; ++e) {
    const int* nodes = model_->element_nodes(e);
    if (std::all_of(nodes, nodes + k, bad)) element = e;
  }
  for (int e = 0; e < model_->num_elements() && element < 0; ++e) {
    const int* nodes = model_->element_nodes(e);
    if (std::find(nodes, nodes + k, node) != nodes + k) element = e;
  }
  std::string nodes;
  for (int a = 0; a < k && element >= 0; ++a)
    nodes += internal::Concat(a ? " " : "", model_->element_nodes(element)[a]);
  FailStep(internal::Concat("elastic force of element ", element, " (nodes ", nodes,
                            ") is not finite at the step-start positions"),
           "force assembly");
}

void DeformableBody::CheckVelocities(const char* stage) {
  const int bad = FindNonFiniteNode(v_);
  if (bad >= 0) FailStep(internal::Concat("non-finite velocity at node ", bad), stage);
  // Kinematic nodes move as prescribed; only free nodes can explode.
  const double max_speed_sq = settings_.max_speed * settings_.max_speed;
  int fastest = -1;
  double fastest_sq = max_speed_sq;
  for (int i = 0; i < num_nodes(); ++i) {
    const double speed_sq = v_.segment<3>(3 * i).squaredNorm();
    if (kinds_[i] == NodeKind::kFree && speed_sq > fastest_sq) {
      fastest = i;
      fastest_sq = speed_sq;
    }
  }
  if (fastest >= 0)
    FailStep(internal::Concat(
                 "node ", fastest, " moves at ", v_.segment<3>(3 * fastest).stableNorm(),
                 " m/s, above max_speed = ", settings_.max_speed, " m/s (the step is exploding)"),
             stage);
}

void DeformableBody::AbortStep() {
  x_ = x0_;
  v_ = v0_;
  external_.setZero();
}

void DeformableBody::FailStep(const std::string& what, const char* stage) {
  AbortStep();
  throw SimulationError(internal::Concat("body '", name(), "': ", what, " (stage: ", stage,
                                         "); state kept at step start"));
}

DeformableBody::State DeformableBody::SaveState() const {
  State state;
  SaveState(state);
  return state;
}

void DeformableBody::SaveState(State& state) const {
  state.x = x_;
  state.v = v_;
  state.external = external_;
  state.kinds = kinds_;
  state.kinematic_targets = kinematic_targets_;
  state.kinds_changed = kinds_changed_;
  // With kinds_changed the restore rebuilds the system and ignores `newton`.
  if (!kinds_changed_) system_.SaveNewtonState(state.newton);
}

void DeformableBody::RestoreState(const State& state) {
  const size_t n = static_cast<size_t>(num_nodes());
  TAUT_DEMAND(state.x.size() == x_.size() && state.v.size() == v_.size() &&
                  state.external.size() == external_.size() && state.kinds.size() == n &&
                  state.kinematic_targets.size() == n,
              "body '", name(), "': RestoreState: the state is of a body with ", state.x.size() / 3,
              " nodes, this one has ", n);
  if (!state.kinds_changed) RestoreSystem(state);
  x_ = state.x;
  v_ = state.v;
  external_ = state.external;
  kinds_ = state.kinds;
  kinematic_targets_ = state.kinematic_targets;
  kinds_changed_ = state.kinds_changed;
}

void DeformableBody::RestoreSystem(const State& state) {
  // The saved system was built for the saved kinds: build it the same way (as the saved body's
  // step did), then put its Newton factor back.
  const bool rebuild = kinds_changed_ || kinds_ != state.kinds;
  if (rebuild) system_.Build(*model_, state.kinds);
  try {
    system_.RestoreNewtonState(state.newton);
  } catch (const InputError& error) {
    kinds_changed_ = kinds_changed_ || rebuild;  // the next step rebuilds for the body's kinds
    throw InputError(internal::Concat("body '", name(), "': RestoreState: ", error.what()));
  }
}

double DeformableBody::CalcKineticEnergy() const {
  double energy = 0.0;
  for (int i = 0; i < num_nodes(); ++i)
    energy += 0.5 * mass_[i] * v_.segment<3>(3 * i).squaredNorm();
  return energy;
}

void DeformableBody::CalcBounds(Vec3& lo, Vec3& hi) const {
  lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  hi = -lo;
  for (int i = 0; i < num_nodes(); ++i) {
    lo = lo.cwiseMin(x_.segment<3>(3 * i));
    hi = hi.cwiseMax(x_.segment<3>(3 * i));
  }
}

}  // namespace taut
