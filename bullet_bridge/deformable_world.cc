#include "bullet_bridge/deformable_world.h"

#include <BulletCollision/CollisionDispatch/btCollisionDispatcher.h>
#include <BulletCollision/CollisionShapes/btPolyhedralConvexShape.h>
#include <BulletDynamics/Dynamics/btRigidBody.h>

#include <algorithm>
#include <chrono>
#include <limits>

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
  entry->island_body = std::make_unique<DeformableIslandBody>(entry->object->body());
  DeformableBody& added = entry->object->body();
  entry->surface = MakeBodyContactSurface(added.model());
  entry->contacts = std::make_unique<RigidContactSource>(added, entry->surface, next_source_id_++,
                                                         added.settings().friction,
                                                         added.settings().contact_margin);
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

RigidIslandBody* DeformableWorld::FindRigidIslandBody(btRigidBody* rigid) {
  auto& slot = rigid_bodies_[rigid];
  if (slot == nullptr) slot = std::make_unique<RigidIslandBody>(rigid);
  return slot.get();
}

void DeformableWorld::AttachNodesToRigidBody(DeformableBody* body, const std::vector<int>& nodes,
                                             const btRigidBody* rigid) {
  Entry& entry = FindEntry(body);
  TAUT_DEMAND(rigid != nullptr, "AttachNodesToRigidBody: rigid body is null");
  // The world's own (non-const) pointer to the rigid body.
  btRigidBody* owned = nullptr;
  for (int i = 0; i < getNumCollisionObjects(); ++i)
    if (getCollisionObjectArray()[i] == rigid) owned = btRigidBody::upcast(getCollisionObjectArray()[i]);
  TAUT_DEMAND(owned != nullptr, "body '", body->name(),
              "': AttachNodesToRigidBody: the rigid body is not in this world");
  const btTransform inverse = rigid->getWorldTransform().inverse();
  std::vector<Vec3> local;
  for (int node : nodes) {
    TAUT_DEMAND(node >= 0 && node < body->num_nodes(), "body '", body->name(),
                "': attached node ", node, " out of range [0, ", body->num_nodes(), ")");
    local.push_back(ToEigen(inverse * ToBullet(body->node_position(node))));
  }
  if (rigid->isStaticOrKinematicObject()) {
    for (int node : nodes) body->SetKinematicTarget(node, body->node_position(node));
    entry.attachments.push_back({rigid, nodes, std::move(local)});
    return;
  }
  entry.dynamic_attachments.push_back(std::make_unique<NodeAttachmentSource>(
      *body, FindRigidIslandBody(owned), nodes, std::move(local), next_source_id_++));
}

void DeformableWorld::SetContactSurface(DeformableBody* body, const SurfaceMesh& surface) {
  Entry& entry = FindEntry(body);
  const auto* hexes = dynamic_cast<const HexElementModel*>(&body->model());
  TAUT_DEMAND(hexes != nullptr, "body '", body->name(),
              "': SetContactSurface needs a hex body (tet bodies touch through their boundary)");
  ContactSurface embedded =
      MakeEmbeddedContactSurface(hexes->lattice(), EmbedSurface(hexes->lattice(), surface));
  entry.contacts->set_surface(embedded);
  // Other deformables still touch the lattice's boundary triangles; this body touches them
  // through the embedded points.
  embedded.triangles = MakeHexContactSurface(hexes->lattice()).triangles;
  embedded.node_triangles = false;
  entry.surface = std::move(embedded);
  for (auto it = pair_contacts_.begin(); it != pair_contacts_.end();)
    it = (it->first.first == &entry || it->first.second == &entry) ? pair_contacts_.erase(it)
                                                                    : std::next(it);
}

void DeformableWorld::ClearLimits(DeformableBody* body) { FindEntry(body).sources.clear(); }

void DeformableWorld::RemoveDeformableBody(DeformableBody* body) {
  auto it = std::find_if(bodies_.begin(), bodies_.end(),
                         [body](const auto& entry) { return &entry->body() == body; });
  TAUT_DEMAND(it != bodies_.end(), "RemoveDeformableBody: body is not in this world");
  removeCollisionObject(&(*it)->collision_object());
  for (auto pair = pair_contacts_.begin(); pair != pair_contacts_.end();)
    pair = (pair->first.first == it->get() || pair->first.second == it->get())
               ? pair_contacts_.erase(pair)
               : std::next(pair);
  bodies_.erase(it);
}

void DeformableWorld::internalSingleStepSimulation(btScalar h) {
  if (bodies_.empty()) {
    btDiscreteDynamicsWorld::internalSingleStepSimulation(h);
    return;
  }
  const auto start = std::chrono::steady_clock::now();
  btDiscreteDynamicsWorld::internalSingleStepSimulation(h);  // calls solveConstraints below
  stats_.ms_total = MsSince(start);
  stats_.ms_rigid = stats_.ms_total - stats_.ms_unconstrained - stats_.ms_rows -
                    stats_.ms_solve - stats_.ms_integrate;
}

void DeformableWorld::UpdateKinematicAttachments() {
  for (auto& entry : bodies_)
    for (const auto& attachment : entry->attachments)
      for (size_t k = 0; k < attachment.nodes.size(); ++k)
        entry->body().SetKinematicTarget(
            attachment.nodes[k],
            ToEigen(attachment.rigid->getWorldTransform() * ToBullet(attachment.local[k])));
}

namespace {
// Bounds of the step's sweep of a deformable body: x0 and x0 + h v*, grown by `margin`.
void CalcSweptBounds(const DeformableBody& body, double h, double margin, Vec3& lo, Vec3& hi) {
  lo.setConstant(std::numeric_limits<double>::infinity());
  hi = -lo;
  const VecX& x0 = body.x0();
  const VecX& v = body.v_star();
  for (int i = 0; i < body.num_nodes(); ++i) {
    const Vec3 p = x0.segment<3>(3 * i);
    const Vec3 q = p + h * v.segment<3>(3 * i);
    lo = lo.cwiseMin(p).cwiseMin(q);
    hi = hi.cwiseMax(p).cwiseMax(q);
  }
  lo.array() -= margin;
  hi.array() += margin;
}

// True when the boxes [lo, hi] and Bullet's proxy bounds overlap.
bool Overlaps(const Vec3& lo, const Vec3& hi, const btBroadphaseProxy& proxy) {
  const Vec3 plo = ToEigen(proxy.m_aabbMin), phi = ToEigen(proxy.m_aabbMax);
  return (lo.array() <= phi.array()).all() && (plo.array() <= hi.array()).all();
}
}  // namespace

int DeformableWorld::DynamicIndex(const btCollisionObject& object) const {
  const int i = object.getWorldArrayIndex();
  return i >= 0 && i < static_cast<int>(dynamic_index_.size()) ? dynamic_index_[i] : -1;
}

void DeformableWorld::BuildIslands(double h, const btContactSolverInfo& info) {
  const int num_deformables = static_cast<int>(bodies_.size());
  const btCollisionObjectArray& objects = getCollisionObjectArray();
  // Dynamic rigid bodies get union-find indices after the deformables.
  dynamic_.clear();
  dynamic_index_.assign(objects.size(), -1);
  for (int i = 0; i < objects.size(); ++i) {
    btRigidBody* rigid = btRigidBody::upcast(objects[i]);
    if (rigid == nullptr || rigid->isStaticOrKinematicObject()) continue;
    if (rigid->getCollisionShape()->getShapeType() == kDeformableShapeType) continue;
    dynamic_index_[i] = num_deformables + static_cast<int>(dynamic_.size());
    dynamic_.push_back(rigid);
  }
  union_find_.Reset(num_deformables + static_cast<int>(dynamic_.size()));
  // Deformable-rigid pairs whose bounds overlap (everything else skips the narrow phase).
  double max_rigid_speed = 0.0;
  for (btRigidBody* rigid : dynamic_)
    max_rigid_speed = std::max(max_rigid_speed, static_cast<double>(rigid->getLinearVelocity().length()));
  for (int d = 0; d < num_deformables; ++d) {
    Entry& entry = *bodies_[d];
    entry.partners.clear();
    CalcSweptBounds(entry.body(), h, entry.body().settings().contact_margin, entry.swept_lo,
                    entry.swept_hi);
    // Rigid partners may move too: grow by their fastest motion this step.
    const Vec3 lo = entry.swept_lo.array() - h * max_rigid_speed;
    const Vec3 hi = entry.swept_hi.array() + h * max_rigid_speed;
    for (int i = 0; i < objects.size(); ++i) {
      const btCollisionObject* object = objects[i];
      if (object->getCollisionShape()->getShapeType() == kDeformableShapeType) continue;
      if (object->hasContactResponse() == false || object->getBroadphaseHandle() == nullptr)
        continue;
      if (!Overlaps(lo, hi, *object->getBroadphaseHandle())) continue;
      // Face planes of polyhedral shapes (made once per shape) give exact inside distances.
      if (object->getCollisionShape()->isPolyhedral() &&
          object->getCollisionShape()->getShapeType() != BOX_SHAPE_PROXYTYPE) {
        auto* shape = const_cast<btPolyhedralConvexShape*>(
            static_cast<const btPolyhedralConvexShape*>(object->getCollisionShape()));
        if (shape->getConvexPolyhedron() == nullptr) shape->initializePolyhedralFeatures();
      }
      if (dynamic_index_[i] >= 0) {
        union_find_.Unite(d, dynamic_index_[i]);
        entry.partners.push_back({object, nullptr});  // rigid island body filled in below
      } else if (object->isStaticOrKinematicObject()) {
        entry.partners.push_back({object, nullptr});
      }
    }
    for (const auto& attachment : entry.dynamic_attachments)
      if (DynamicIndex(*attachment->rigid()->rigid()) >= 0)
        union_find_.Unite(d, DynamicIndex(*attachment->rigid()->rigid()));
  }
  // Deformables whose swept bounds overlap share an island and a pair contact source.
  active_pairs_.clear();
  for (int d = 0; d < num_deformables; ++d) {
    for (int e = d + 1; e < num_deformables; ++e) {
      const Entry& first = *bodies_[d];
      const Entry& second = *bodies_[e];
      if ((first.swept_lo.array() > second.swept_hi.array()).any() ||
          (second.swept_lo.array() > first.swept_hi.array()).any())
        continue;
      union_find_.Unite(d, e);
      auto& source = pair_contacts_[{&first, &second}];
      if (source == nullptr) {
        const DeformableBodySettings& a = first.object->body().settings();
        const DeformableBodySettings& b = second.object->body().settings();
        source = std::make_unique<DeformableContactSource>(
            first.object->body(), first.surface, second.object->body(), second.surface,
            next_source_id_++, a.friction * b.friction,
            std::max(a.contact_margin, b.contact_margin));
      }
      active_pairs_.emplace_back(d, source.get());
    }
  }
  // Rigid bodies touching each other (Bullet's manifolds with points) share an island.
  btDispatcher* dispatcher = getDispatcher();
  for (int m = 0; m < dispatcher->getNumManifolds(); ++m) {
    const btPersistentManifold* manifold = dispatcher->getManifoldByIndexInternal(m);
    if (manifold->getNumContacts() == 0) continue;
    const int a = DynamicIndex(*manifold->getBody0());
    const int b = DynamicIndex(*manifold->getBody1());
    if (a >= 0 && b >= 0) union_find_.Unite(a, b);
  }
  // So do rigid bodies joined by Bullet joints.
  for (int j = 0; j < getNumConstraints(); ++j) {
    const btTypedConstraint* joint = getConstraint(j);
    if (!joint->isEnabled()) continue;
    const int a = DynamicIndex(joint->getRigidBodyA());
    const int b = DynamicIndex(joint->getRigidBodyB());
    if (a >= 0 && b >= 0) union_find_.Unite(a, b);
  }
  // Islands: one per root that holds a deformable (deformables are the lowest indices, so the
  // root of an island with deformables is its first deformable).
  island_of_root_.assign(num_deformables, -1);
  num_islands_ = 0;
  for (int d = 0; d < num_deformables; ++d) {
    const int root = union_find_.Find(d);
    if (island_of_root_[root] < 0) {
      if (static_cast<int>(islands_.size()) <= num_islands_) islands_.emplace_back();
      Island& island = islands_[num_islands_];
      island.bodies.clear();
      island.sources.clear();
      if (island.manifolds == nullptr)
        island.manifolds = std::make_unique<RigidManifoldSource>(next_source_id_++);
      if (island.joints == nullptr) island.joints = std::make_unique<JointSource>(next_source_id_++);
      island.manifolds->Clear();
      island.joints->Clear();
      island.first_entry = d;
      island_of_root_[root] = num_islands_++;
    }
    Entry& entry = *bodies_[d];
    entry.island = island_of_root_[root];
    islands_[entry.island].bodies.push_back(entry.island_body.get());
  }
  // Coupled rigid bodies: start their step before Bullet's solver changes their velocity.
  coupled_.clear();
  for (size_t k = 0; k < dynamic_.size(); ++k) {
    const int root = union_find_.Find(num_deformables + static_cast<int>(k));
    if (root >= num_deformables) continue;  // a rigid island: Bullet's alone
    RigidIslandBody* body = FindRigidIslandBody(dynamic_[k]);
    dynamic_[k]->activate();  // Bullet's sleeping test does not see deformable contacts
    body->BeginStep(h);
    coupled_.push_back(body);
    islands_[island_of_root_[root]].bodies.push_back(body);
  }
  for (auto& entry : bodies_)
    for (ContactPartner& partner : entry->partners) {
      const int index = DynamicIndex(*partner.object);
      if (index >= 0) partner.rigid = FindRigidIslandBody(dynamic_[index - num_deformables]);
    }
  // Manifolds touching a coupled body go into its island's SQP.
  for (int m = 0; m < dispatcher->getNumManifolds(); ++m) {
    const btPersistentManifold* manifold = dispatcher->getManifoldByIndexInternal(m);
    if (manifold->getNumContacts() == 0) continue;
    int root = -1;
    const RigidIslandBody* sides[2] = {nullptr, nullptr};
    const btCollisionObject* objects_ab[2] = {manifold->getBody0(), manifold->getBody1()};
    for (int s = 0; s < 2; ++s) {
      const int index = DynamicIndex(*objects_ab[s]);
      if (index < 0) continue;
      const int r = union_find_.Find(index);
      if (r >= num_deformables) continue;
      root = r;
      sides[s] = FindRigidIslandBody(dynamic_[index - num_deformables]);
    }
    if (root >= 0)
      islands_[island_of_root_[root]].manifolds->AddManifold(*manifold, sides[0], sides[1], info);
  }
  // Joints touching a coupled body too.
  for (int j = 0; j < getNumConstraints(); ++j) {
    btTypedConstraint* joint = getConstraint(j);
    const btRigidBody* bodies[2] = {&joint->getRigidBodyA(), &joint->getRigidBodyB()};
    const RigidIslandBody* sides[2] = {nullptr, nullptr};
    int root = -1;
    for (int s = 0; s < 2; ++s) {
      const int index = DynamicIndex(*bodies[s]);
      if (index < 0) continue;
      const int r = union_find_.Find(index);
      if (r >= num_deformables) continue;
      root = r;
      sides[s] = FindRigidIslandBody(dynamic_[index - num_deformables]);
    }
    if (root >= 0) islands_[island_of_root_[root]].joints->AddJoint(*joint, sides[0], sides[1], info);
  }
  // Row sources of each island.
  for (auto& entry : bodies_) {
    Island& island = islands_[entry->island];
    for (auto& source : entry->sources) island.sources.push_back(source.get());
    if (!entry->partners.empty()) {
      entry->contacts->set_partners(entry->partners);
      island.sources.push_back(entry->contacts.get());
    }
    for (auto& attachment : entry->dynamic_attachments) island.sources.push_back(attachment.get());
  }
  for (const auto& [d, source] : active_pairs_) islands_[bodies_[d]->island].sources.push_back(source);
  for (int i = 0; i < num_islands_; ++i) {
    if (islands_[i].manifolds->num_points() > 0)
      islands_[i].sources.push_back(islands_[i].manifolds.get());
    if (islands_[i].joints->num_rows() > 0) islands_[i].sources.push_back(islands_[i].joints.get());
  }
}

void DeformableWorld::AccumulateStats(const StepStats& island_stats) {
  stats_.ms_rows += island_stats.ms_rows;
  stats_.ms_solve += island_stats.ms_solve;
  stats_.rows_strain += island_stats.rows_strain;
  stats_.rows_energy += island_stats.rows_energy;
  stats_.rows_contact += island_stats.rows_contact;
  stats_.rows_rigid_contact += island_stats.rows_rigid_contact;
  stats_.rows_joint += island_stats.rows_joint;
  stats_.pgs_sweeps += island_stats.pgs_sweeps;
  stats_.sqp_iterations = std::max(stats_.sqp_iterations, island_stats.sqp_iterations);
  stats_.restoration_iterations += island_stats.restoration_iterations;
  stats_.active_set_solves += island_stats.active_set_solves;
  stats_.stationarity = std::max(stats_.stationarity, island_stats.stationarity);
  stats_.lcp_residual = std::max(stats_.lcp_residual, island_stats.lcp_residual);
  stats_.violation_before = std::max(stats_.violation_before, island_stats.violation_before);
  stats_.violation_after = std::max(stats_.violation_after, island_stats.violation_after);
  stats_.converged = stats_.converged && island_stats.converged;
  stats_.islands_dual += island_stats.islands_dual;
  stats_.islands_primal += island_stats.islands_primal;
  stats_.newton_iterations += island_stats.newton_iterations;
  stats_.pcg_iterations += island_stats.pcg_iterations;
  stats_.kkt_primal = std::max(stats_.kkt_primal, island_stats.kkt_primal);
  stats_.kkt_complementarity = std::max(stats_.kkt_complementarity, island_stats.kkt_complementarity);
  stats_.kkt_dual = std::max(stats_.kkt_dual, island_stats.kkt_dual);
  for (int i = 0; i < 5; ++i) {
    stats_.kkt_primal_by_type[i] = std::max(stats_.kkt_primal_by_type[i], island_stats.kkt_primal_by_type[i]);
    stats_.kkt_complementarity_by_type[i] =
        std::max(stats_.kkt_complementarity_by_type[i], island_stats.kkt_complementarity_by_type[i]);
  }
}

void DeformableWorld::solveConstraints(btContactSolverInfo& info) {
  if (bodies_.empty()) {
    btDiscreteDynamicsWorld::solveConstraints(info);
    return;
  }
  const double h = static_cast<double>(info.m_timeStep);
  stats_ = StepStats();
  coupled_.clear();
  int begun = 0;
  try {
    StepDeformables(h, info, begun);
  } catch (const SimulationError&) {
    // A body failed (it restored itself): every other body goes back to the step start too, so
    // the world stays consistent at the last good state.
    for (int b = 0; b < begun; ++b) bodies_[b]->body().AbortStep();
    for (RigidIslandBody* rigid : coupled_) rigid->AbortStep();
    throw;
  }
}

void DeformableWorld::StepDeformables(double h, btContactSolverInfo& info, int& begun) {
  // Stage 2: unconstrained implicit step of every deformable body.
  const Vec3 gravity = ToEigen(getGravity());
  UpdateKinematicAttachments();
  auto t = std::chrono::steady_clock::now();
  for (auto& entry : bodies_) {
    ++begun;
    entry->body().BeginStep(h, gravity);
  }
  stats_.ms_unconstrained = MsSince(t);
  // Stage 3: islands; then Bullet's solver for every rigid island (bodies coupled to
  // deformables are restored and solved again below, with the deformables).
  t = std::chrono::steady_clock::now();
  BuildIslands(h, info);
  stats_.ms_rows += MsSince(t);
  btDiscreteDynamicsWorld::solveConstraints(info);
  // Stages 4-6: one SQP per island with rows (no rows: no LCP at all).
  for (int i = 0; i < num_islands_; ++i) {
    Island& island = islands_[i];
    if (island.sources.empty()) continue;
    StepStats island_stats;
    bodies_[island.first_entry]->solver.Solve(h, island.bodies, island.sources, solver_settings_,
                                              island_stats);
    AccumulateStats(island_stats);
    stats_.islands++;
  }
  stats_.rigid_bodies_coupled = static_cast<int>(coupled_.size());
  // Stage 7: x = x0 + h v (Bullet integrates the rigid transforms next).
  t = std::chrono::steady_clock::now();
  for (auto& entry : bodies_) entry->body().EndStep(h);
  for (RigidIslandBody* rigid : coupled_) rigid->EndStep();
  stats_.ms_integrate = MsSince(t);
}

}  // namespace taut
