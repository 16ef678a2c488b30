#include "bullet_bridge/deformable_world.h"

#include <BulletCollision/CollisionDispatch/btCollisionDispatcher.h>
#include <BulletDynamics/Dynamics/btRigidBody.h>

#include <algorithm>
#include <chrono>

#include "bullet_bridge/eigen_bullet.h"
#include "plugin/tet_element_model.h"

namespace taut {

namespace {
// Milliseconds since `start`.
double MsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}
}  // namespace

DeformableWorld::DeformableWorld(btDispatcher* dispatcher, btBroadphaseInterface* broadphase,
                                 btConstraintSolver* solver,
                                 btCollisionConfiguration* configuration)
    : btDiscreteDynamicsWorld(dispatcher, broadphase, solver, configuration) {
  // Bullet must never build contact manifolds for deformables: taut detects those itself.
  if (auto* collision_dispatcher = dynamic_cast<btCollisionDispatcher*>(dispatcher)) {
    for (int type = 0; type < MAX_BROADPHASE_COLLISION_TYPES; ++type) {
      collision_dispatcher->registerCollisionCreateFunc(kDeformableShapeType, type,
                                                        &empty_algorithm_);
      collision_dispatcher->registerCollisionCreateFunc(type, kDeformableShapeType,
                                                        &empty_algorithm_);
    }
  }
}

DeformableWorld::~DeformableWorld() {
  for (auto& body : bodies_) removeCollisionObject(&body->collision_object());
}

DeformableBody* DeformableWorld::AddTetBody(const TetMesh& mesh,
                                            const DeformableBodySettings& settings) {
  return AddTetBody(std::make_shared<const TetMesh>(mesh), settings);
}

DeformableBody* DeformableWorld::AddTetBody(std::shared_ptr<const TetMesh> mesh,
                                            const DeformableBodySettings& settings) {
  auto model = std::make_unique<TetElementModel>(std::move(mesh), settings.material);
  return AddDeformableBody(std::make_unique<DeformableBody>(std::move(model), settings));
}

DeformableBody* DeformableWorld::AddHexBody(const HexLattice& lattice,
                                            const DeformableBodySettings& settings,
                                            HexRotationMethod method) {
  return AddHexBody(std::make_shared<const HexLattice>(lattice), settings, method);
}

DeformableBody* DeformableWorld::AddHexBody(std::shared_ptr<const HexLattice> lattice,
                                            const DeformableBodySettings& settings,
                                            HexRotationMethod method) {
  auto model = std::make_unique<HexElementModel>(std::move(lattice), settings.material, method);
  return AddDeformableBody(std::make_unique<DeformableBody>(std::move(model), settings));
}

DeformableBody* DeformableWorld::AddDeformableBody(std::unique_ptr<DeformableBody> body) {
  TAUT_DEMAND(body != nullptr, "AddDeformableBody: body is null");
  auto entry = std::make_unique<Entry>();
  entry->object = std::make_unique<DeformableCollisionObject>(std::move(body));
  bodies_.push_back(std::move(entry));
  addCollisionObject(&bodies_.back()->collision_object(), btBroadphaseProxy::DefaultFilter,
                     btBroadphaseProxy::AllFilter);
  return &bodies_.back()->body();
}

DeformableWorld::Entry& DeformableWorld::FindEntry(const DeformableBody* body) {
  for (auto& entry : bodies_)
    if (&entry->body() == body) return *entry;
  throw InputError("deformable body is not in this world");
}

template <typename T>
T* DeformableWorld::ReplaceSource(DeformableBody* body, std::unique_ptr<T> source) {
  auto& sources = FindEntry(body).sources;
  sources.erase(std::remove_if(sources.begin(), sources.end(),
                               [](const auto& s) { return dynamic_cast<T*>(s.get()) != nullptr; }),
                sources.end());
  T* result = source.get();
  sources.push_back(std::move(source));
  return result;
}

StrainLimitConstraint* DeformableWorld::SetStrainLimits(DeformableBody* body,
                                                        const StrainLimitSettings& limits) {
  FindEntry(body);  // names a foreign body before anything is built
  return ReplaceSource(
      body, std::make_unique<StrainLimitConstraint>(*body, limits, next_source_id_++));
}

EnergyLimitConstraint* DeformableWorld::SetEnergyLimits(DeformableBody* body,
                                                        const EnergyLimitSettings& limits) {
  FindEntry(body);
  return ReplaceSource(
      body, std::make_unique<EnergyLimitConstraint>(*body, limits, next_source_id_++));
}

void DeformableWorld::AttachNodesToRigidBody(DeformableBody* body, const std::vector<int>& nodes,
                                             const btRigidBody* rigid) {
  Entry& entry = FindEntry(body);
  TAUT_DEMAND(rigid != nullptr, "AttachNodesToRigidBody: rigid body is null");
  Entry::Attachment attachment{rigid, nodes, {}};
  const btTransform inverse = rigid->getWorldTransform().inverse();
  for (int node : nodes) {
    TAUT_DEMAND(node >= 0 && node < body->num_nodes(), "body '", body->name(),
                "': attached node ", node, " out of range [0, ", body->num_nodes(), ")");
    attachment.local.push_back(ToEigen(inverse * ToBullet(body->node_position(node))));
    body->SetKinematicTarget(node, body->node_position(node));
  }
  entry.attachments.push_back(std::move(attachment));
}

void DeformableWorld::ClearLimits(DeformableBody* body) { FindEntry(body).sources.clear(); }

void DeformableWorld::RemoveDeformableBody(DeformableBody* body) {
  auto it = std::find_if(bodies_.begin(), bodies_.end(),
                         [body](const auto& entry) { return &entry->body() == body; });
  TAUT_DEMAND(it != bodies_.end(), "RemoveDeformableBody: body is not in this world");
  removeCollisionObject(&(*it)->collision_object());
  bodies_.erase(it);
}

void DeformableWorld::internalSingleStepSimulation(btScalar h) {
  if (bodies_.empty()) {
    btDiscreteDynamicsWorld::internalSingleStepSimulation(h);
    return;
  }
  const auto start = std::chrono::steady_clock::now();
  stats_ = StepStats();
  StepDeformableBodies(static_cast<double>(h));
  const auto rigid_start = std::chrono::steady_clock::now();
  btDiscreteDynamicsWorld::internalSingleStepSimulation(h);  // also refreshes every AABB
  stats_.ms_rigid = MsSince(rigid_start);
  stats_.ms_total = MsSince(start);
}

void DeformableWorld::CollectStaticObjects(std::vector<const btCollisionObject*>& objects) const {
  objects.clear();
  const btCollisionObjectArray& all = getCollisionObjectArray();
  for (int i = 0; i < all.size(); ++i) {
    const btCollisionObject* object = all[i];
    if (object->getCollisionShape()->getShapeType() == kDeformableShapeType) continue;
    if (object->isStaticOrKinematicObject()) objects.push_back(object);
  }
}

void DeformableWorld::StepDeformableBodies(double h) {
  const Vec3 gravity = ToEigen(getGravity());
  // Attached nodes follow their rigid bodies' current frames.
  for (auto& entry : bodies_)
    for (const auto& attachment : entry->attachments)
      for (size_t k = 0; k < attachment.nodes.size(); ++k)
        entry->body().SetKinematicTarget(
            attachment.nodes[k],
            ToEigen(attachment.rigid->getWorldTransform() * ToBullet(attachment.local[k])));
  auto t = std::chrono::steady_clock::now();
  for (auto& entry : bodies_) entry->body().BeginStep(h, gravity);
  stats_.ms_unconstrained = MsSince(t);
  // Limits and contacts with static/kinematic rigid objects: one SQP per constrained body (these
  // rows couple no bodies).
  std::vector<const btCollisionObject*> objects;
  CollectStaticObjects(objects);
  std::vector<DeformableBody*> island(1);
  std::vector<ConstraintSource*> sources;
  for (auto& entry : bodies_) {
    DeformableBody& body = entry->body();
    if (!objects.empty() && entry->contacts == nullptr)
      entry->contacts = std::make_unique<RigidContactSource>(
          body, next_source_id_++, body.settings().friction, body.settings().contact_margin);
    if (entry->sources.empty() && objects.empty()) continue;
    island[0] = &body;
    sources.clear();
    for (auto& source : entry->sources) sources.push_back(source.get());
    if (!objects.empty()) {
      entry->contacts->set_objects(objects);
      sources.push_back(entry->contacts.get());
    }
    StepStats body_stats;
    entry->solver.Solve(h, island, sources, solver_settings_, body_stats);
    stats_.ms_rows += body_stats.ms_rows;
    stats_.ms_solve += body_stats.ms_solve;
    stats_.rows_strain += body_stats.rows_strain;
    stats_.rows_energy += body_stats.rows_energy;
    stats_.rows_contact += body_stats.rows_contact;
    stats_.pgs_sweeps += body_stats.pgs_sweeps;
    stats_.sqp_iterations = std::max(stats_.sqp_iterations, body_stats.sqp_iterations);
    stats_.restoration_iterations += body_stats.restoration_iterations;
    stats_.active_set_solves += body_stats.active_set_solves;
    stats_.stationarity = std::max(stats_.stationarity, body_stats.stationarity);
    stats_.violation_before = std::max(stats_.violation_before, body_stats.violation_before);
    stats_.violation_after = std::max(stats_.violation_after, body_stats.violation_after);
    stats_.converged = stats_.converged && body_stats.converged;
  }
  t = std::chrono::steady_clock::now();
  for (auto& entry : bodies_) entry->body().EndStep(h);
  stats_.ms_integrate = MsSince(t);
}

}  // namespace taut
