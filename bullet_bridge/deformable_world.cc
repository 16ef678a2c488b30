#include "bullet_bridge/deformable_world.h"

#include <BulletCollision/CollisionDispatch/btCollisionDispatcher.h>
#include <BulletCollision/CollisionShapes/btCompoundShape.h>
#include <BulletCollision/CollisionShapes/btPolyhedralConvexShape.h>
#include <BulletDynamics/Dynamics/btRigidBody.h>
#include <BulletDynamics/Featherstone/btMultiBodyLinkCollider.h>

#include <algorithm>
#include <chrono>
#include <limits>
#include <type_traits>

#include "bullet_bridge/body_pose.h"
#include "bullet_bridge/collision_filter.h"
#include "bullet_bridge/eigen_bullet.h"
#include "plugin/cholmod_cholesky.h"
#include "plugin/tet_element_model.h"

namespace taut {

namespace {
// Lends `runner` to a body's element loops for one scope (also when the step throws): only while
// no pool task runs, since the pool's Run is not reentrant.
class LentLoopRunner {
 public:
  LentLoopRunner(DeformableBody& body, ElementLoopRunner* runner) : body_(body) {
    body_.set_element_loop_runner(runner);
  }
  ~LentLoopRunner() { body_.set_element_loop_runner(nullptr); }
  LentLoopRunner(const LentLoopRunner&) = delete;
  LentLoopRunner& operator=(const LentLoopRunner&) = delete;

 private:
  DeformableBody& body_;
};

// Milliseconds since `start`.
double MsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// Milliseconds since `lap`, which then restarts at now (stage timers; no allocation).
double LapMs(std::chrono::steady_clock::time_point& lap) {
  const auto now = std::chrono::steady_clock::now();
  const double ms = std::chrono::duration<double, std::milli>(now - lap).count();
  lap = now;
  return ms;
}
}  // namespace

template <class BulletWorld>
DeformableWorldOf<BulletWorld>::DeformableWorldOf(btDispatcher* dispatcher,
                                                  btBroadphaseInterface* broadphase, Solver* solver,
                                                  btCollisionConfiguration* configuration)
    : BulletWorld(dispatcher, broadphase, solver, configuration) {
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

template <class BulletWorld>
DeformableWorldOf<BulletWorld>::~DeformableWorldOf() {
  for (auto& body : bodies_) this->removeCollisionObject(&body->collision_object());
}

template <class BulletWorld>
DeformableBody* DeformableWorldOf<BulletWorld>::AddTetBody(const TetMesh& mesh,
                                                           const DeformableBodySettings& settings) {
  return AddTetBody(std::make_shared<const TetMesh>(mesh), settings);
}

template <class BulletWorld>
DeformableBody* DeformableWorldOf<BulletWorld>::AddTetBody(std::shared_ptr<const TetMesh> mesh,
                                                           const DeformableBodySettings& settings) {
  auto model = std::make_unique<TetElementModel>(std::move(mesh), settings.material);
  return AddDeformableBody(std::make_unique<DeformableBody>(std::move(model), settings));
}

template <class BulletWorld>
DeformableBody* DeformableWorldOf<BulletWorld>::AddHexBody(const HexLattice& lattice,
                                                           const DeformableBodySettings& settings,
                                                           HexRotationMethod method) {
  return AddHexBody(std::make_shared<const HexLattice>(lattice), settings, method);
}

template <class BulletWorld>
DeformableBody* DeformableWorldOf<BulletWorld>::AddHexBody(
    std::shared_ptr<const HexLattice> lattice, const DeformableBodySettings& settings,
    HexRotationMethod method) {
  auto model = std::make_unique<HexElementModel>(std::move(lattice), settings.material, method);
  return AddDeformableBody(std::make_unique<DeformableBody>(std::move(model), settings));
}

template <class BulletWorld>
DeformableBody* DeformableWorldOf<BulletWorld>::AddTetBody(const TetMesh& mesh,
                                                           const DeformableBodySettings& settings,
                                                           const btTransform& pose) {
  return AddTetBody(std::make_shared<const TetMesh>(mesh), settings, pose);
}

template <class BulletWorld>
DeformableBody* DeformableWorldOf<BulletWorld>::AddTetBody(std::shared_ptr<const TetMesh> mesh,
                                                           const DeformableBodySettings& settings,
                                                           const btTransform& pose) {
  auto body = std::make_unique<DeformableBody>(
      std::make_unique<TetElementModel>(std::move(mesh), settings.material), settings);
  PlaceAtPose(*body, pose);  // before the broadphase sees its bounds
  return AddDeformableBody(std::move(body));
}

template <class BulletWorld>
DeformableBody* DeformableWorldOf<BulletWorld>::AddHexBody(const HexLattice& lattice,
                                                           const DeformableBodySettings& settings,
                                                           const btTransform& pose,
                                                           HexRotationMethod method) {
  return AddHexBody(std::make_shared<const HexLattice>(lattice), settings, pose, method);
}

template <class BulletWorld>
DeformableBody* DeformableWorldOf<BulletWorld>::AddHexBody(
    std::shared_ptr<const HexLattice> lattice, const DeformableBodySettings& settings,
    const btTransform& pose, HexRotationMethod method) {
  auto body = std::make_unique<DeformableBody>(
      std::make_unique<HexElementModel>(std::move(lattice), settings.material, method), settings);
  PlaceAtPose(*body, pose);
  return AddDeformableBody(std::move(body));
}

template <class BulletWorld>
DeformableBody* DeformableWorldOf<BulletWorld>::AddDeformableBody(
    std::unique_ptr<DeformableBody> body) {
  TAUT_DEMAND(body != nullptr, "AddDeformableBody: body is null");
  auto entry = std::make_unique<Entry>();
  entry->object = std::make_unique<DeformableCollisionObject>(std::move(body));
  entry->island_body = std::make_unique<DeformableIslandBody>(entry->object->body());
  DeformableBody& added = entry->object->body();
  entry->surface = MakeBodyContactSurface(added.model());
  entry->contacts = std::make_unique<RigidContactSource>(
      added, entry->surface, next_source_id_++, added.settings().friction,
      added.settings().contact_margin, added.settings().restitution);
  entry->contacts->set_face_contact(added.settings().face_contact);
  bodies_.push_back(std::move(entry));
  this->addCollisionObject(&bodies_.back()->collision_object(), btBroadphaseProxy::DefaultFilter,
                           btBroadphaseProxy::AllFilter);
  return &bodies_.back()->body();
}

template <class BulletWorld>
typename DeformableWorldOf<BulletWorld>::Entry& DeformableWorldOf<BulletWorld>::FindEntry(
    const DeformableBody* body) {
  for (auto& entry : bodies_)
    if (&entry->body() == body) return *entry;
  throw InputError("deformable body is not in this world");
}

template <class BulletWorld>
template <typename T>
T* DeformableWorldOf<BulletWorld>::ReplaceSource(DeformableBody* body, std::unique_ptr<T> source) {
  auto& sources = FindEntry(body).sources;
  sources.erase(std::remove_if(sources.begin(), sources.end(),
                               [](const auto& s) { return dynamic_cast<T*>(s.get()) != nullptr; }),
                sources.end());
  T* result = source.get();
  sources.push_back(std::move(source));
  return result;
}

template <class BulletWorld>
StrainLimitSource* DeformableWorldOf<BulletWorld>::SetStrainLimits(
    DeformableBody* body, const StrainLimitSettings& limits) {
  FindEntry(body);  // names a foreign body before anything is built
  return ReplaceSource(body, std::make_unique<StrainLimitSource>(*body, limits, next_source_id_++));
}

template <class BulletWorld>
EnergyLimitSource* DeformableWorldOf<BulletWorld>::SetEnergyLimits(
    DeformableBody* body, const EnergyLimitSettings& limits) {
  FindEntry(body);
  return ReplaceSource(body, std::make_unique<EnergyLimitSource>(*body, limits, next_source_id_++));
}

template <class BulletWorld>
NodeHeightSource* DeformableWorldOf<BulletWorld>::SetNodeHeightLimit(DeformableBody* body,
                                                                     double z_min) {
  FindEntry(body);
  return ReplaceSource(body, std::make_unique<NodeHeightSource>(
                                 *body, z_min, body->settings().contact_margin, next_source_id_++));
}

template <class BulletWorld>
RigidIslandBody* DeformableWorldOf<BulletWorld>::FindRigidIslandBody(btRigidBody* rigid) {
  auto& slot = rigid_bodies_[rigid];
  if (slot == nullptr) slot = std::make_unique<RigidIslandBody>(rigid);
  return slot.get();
}

template <class BulletWorld>
void DeformableWorldOf<BulletWorld>::AttachNodesToRigidBody(DeformableBody* body,
                                                            const std::vector<int>& nodes,
                                                            const btRigidBody* rigid) {
  Entry& entry = FindEntry(body);
  TAUT_DEMAND(rigid != nullptr, "AttachNodesToRigidBody: rigid body is null");
  // The world's own (non-const) pointer to the rigid body.
  btRigidBody* owned = nullptr;
  for (int i = 0; i < this->getNumCollisionObjects(); ++i)
    if (this->getCollisionObjectArray()[i] == rigid)
      owned = btRigidBody::upcast(this->getCollisionObjectArray()[i]);
  TAUT_DEMAND(owned != nullptr, "body '", body->name(),
              "': AttachNodesToRigidBody: the rigid body is not in this world");
  const btTransform inverse = rigid->getWorldTransform().inverse();
  std::vector<Vec3> local;
  for (int node : nodes) {
    TAUT_DEMAND(node >= 0 && node < body->num_nodes(), "body '", body->name(), "': attached node ",
                node, " out of range [0, ", body->num_nodes(), ")");
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

template <class BulletWorld>
void DeformableWorldOf<BulletWorld>::SetContactSurface(DeformableBody* body,
                                                       const SurfaceMesh& surface) {
  Entry& entry = FindEntry(body);
  ContactSurface embedded;
  try {
    embedded = MakeEmbeddedBodyContactSurface(body->model(), surface);
  } catch (const InputError& error) {
    throw InputError(
        internal::Concat("body '", body->name(), "': SetContactSurface: ", error.what()));
  }
  entry.contacts->set_surface(embedded);
  // Other deformables still touch the body's boundary triangles (lattice or tet boundary); this
  // body touches them through the embedded points.
  embedded.triangles = MakeBodyContactSurface(body->model()).triangles;
  embedded.node_triangles = false;
  entry.surface = std::move(embedded);
  for (auto it = pair_contacts_.begin(); it != pair_contacts_.end();)
    it = (it->first.first == &entry || it->first.second == &entry) ? pair_contacts_.erase(it)
                                                                   : std::next(it);
}

template <class BulletWorld>
void DeformableWorldOf<BulletWorld>::ClearLimits(DeformableBody* body) {
  FindEntry(body).sources.clear();
}

template <class BulletWorld>
void DeformableWorldOf<BulletWorld>::SetThreadCount(int num_threads) {
  TAUT_DEMAND(num_threads >= 1, "DeformableWorld::SetThreadCount: thread count must be >= 1, got ",
              num_threads);
  if (num_threads == thread_count()) return;
  pool_.reset();  // joins the old workers first
  if (num_threads > 1) pool_ = std::make_unique<IslandThreadPool>(num_threads);
}

template <class BulletWorld>
void DeformableWorldOf<BulletWorld>::RemoveDeformableBody(DeformableBody* body) {
  auto it = std::find_if(bodies_.begin(), bodies_.end(),
                         [body](const auto& entry) { return &entry->body() == body; });
  TAUT_DEMAND(it != bodies_.end(), "RemoveDeformableBody: body is not in this world");
  this->removeCollisionObject(&(*it)->collision_object());
  forces_.Clear(forces_.h);  // they may name the body
  islands_solved_ = false;
  for (auto pair = pair_contacts_.begin(); pair != pair_contacts_.end();)
    pair = (pair->first.first == it->get() || pair->first.second == it->get())
               ? pair_contacts_.erase(pair)
               : std::next(pair);
  bodies_.erase(it);
}

template <class BulletWorld>
int DeformableWorldOf<BulletWorld>::stepSimulation(btScalar time_step, int max_sub_steps,
                                                   btScalar fixed_time_step) {
  ValidateSqpSettings(solver_settings_);  // before any state moves: a bad setting changes nothing
  call_stats_ = StepStats();
  call_stats_.substeps = 0;
  return BulletWorld::stepSimulation(time_step, max_sub_steps, fixed_time_step);
}

template <class BulletWorld>
void DeformableWorldOf<BulletWorld>::internalSingleStepSimulation(btScalar h) {
  if (bodies_.empty()) {
    BulletWorld::internalSingleStepSimulation(h);
    call_stats_.substeps++;
    return;
  }
  const auto start = std::chrono::steady_clock::now();
  BulletWorld::internalSingleStepSimulation(h);  // calls solveConstraints below
  stats_.ms_total = MsSince(start);
  // From the stages' wall times: with several threads the islands' ms_rows and ms_solve are
  // summed over threads and may exceed the time their stage took.
  stats_.ms_rigid = stats_.ms_total - stats_.ms_unconstrained - stats_.ms_stage_partners -
                    stats_.ms_stage_islands - stats_.ms_stage_couple_rigid -
                    stats_.ms_stage_row_sources - stats_.ms_stage_solve_islands -
                    stats_.ms_integrate;
  AddSubstepStats(stats_, call_stats_);
}

template <class BulletWorld>
void DeformableWorldOf<BulletWorld>::UpdateKinematicAttachments() {
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

// Upper bound of the speed [m/s] of the points of a multibody link's collider: the speed of its
// frame's origin plus its angular speed times the collider's bounding radius (the link's spatial
// velocity from Bullet's last articulated-body pass).
double EstimateLinkSpeed(const btMultiBodyLinkCollider& link) {
  const btMultiBody* body = link.m_multiBody;
  if (body == nullptr || link.isStaticOrKinematicObject()) return 0.0;
  btVector3 linear = body->getBaseVel(), angular = body->getBaseOmega();
  if (link.m_link >= 0) {
    linear = body->getLink(link.m_link).m_absFrameTotVelocity.getLinear();
    angular = body->getLink(link.m_link).m_absFrameTotVelocity.getAngular();
  }
  btVector3 center;
  btScalar radius;
  link.getCollisionShape()->getBoundingSphere(center, radius);
  return static_cast<double>(linear.length() + angular.length() * (radius + center.length()));
}

// Keeps a multibody and its link colliders awake.
void WakeMultiBody(btMultiBody& body) {
  body.wakeUp();
  if (body.getBaseCollider() != nullptr) body.getBaseCollider()->activate();
  for (int l = 0; l < body.getNumLinks(); ++l)
    if (body.getLinkCollider(l) != nullptr) body.getLinkCollider(l)->activate();
}

// Narrowphase set-up of a contact partner's shape, once per shape when a deformable first comes
// near it: face planes of polyhedral shapes give exact inside distances (point_shape_distance.cc);
// boxes have their own closed form. Not done when the shape is added to the world: face planes
// also switch Bullet's own convex-convex contacts to polyhedral clipping, which must stay stock
// for rigid objects no deformable comes near.
void PrepareNarrowphaseShape(btCollisionShape& shape) {
  if (!shape.isPolyhedral() || shape.getShapeType() == BOX_SHAPE_PROXYTYPE) return;
  auto& polyhedral = static_cast<btPolyhedralConvexShape&>(shape);
  if (polyhedral.getConvexPolyhedron() == nullptr) polyhedral.initializePolyhedralFeatures();
}
}  // namespace

template <class BulletWorld>
void DeformableWorldOf<BulletWorld>::StepDeformables(double h, btContactSolverInfo& info,
                                                     int& begun) {
  auto lap = std::chrono::steady_clock::now();
  BeginDeformableSteps(h, begun);  // 2. unconstrained deformable step
  stats_.ms_stage_begin_steps = LapMs(lap);
  FindContactPartners(h);  // 3. collision detection: deformables vs rigid objects and each other
  stats_.ms_stage_partners = LapMs(lap);
  UniteIslands();  // 4. islands
  stats_.ms_stage_islands = LapMs(lap);
  CoupleRigidBodies(h);  // 4. rigid bodies of deformable islands
  stats_.ms_stage_couple_rigid = LapMs(lap);
  GatherRowSources(info);  // 5. rows per island
  stats_.ms_stage_row_sources = LapMs(lap);
  SuspendMotors();                    // 6. motors of coupled multibodies are island rows
  SolveRigidIslandsWithBullet(info);  // 6. rigid-only islands
  ResumeMotors();
  CoupleMultiBodies(h);  // 6. multibodies of deformable islands, from Bullet's answer
  stats_.ms_stage_bullet_solver = LapMs(lap);
  SolveIslands(h);  // 6. deformable islands
  stats_.ms_stage_solve_islands = LapMs(lap);
  EndSteps(h);     // 7. integrate (Bullet integrates the rigid transforms next)
  ReportForces();  // 8. forces out (timed with stage 7: a copy of the solved rows)
  islands_solved_ = true;
  stats_.ms_stage_end_steps = LapMs(lap);
  SumStageStats();  // 8. stats
}

template <class BulletWorld>
void DeformableWorldOf<BulletWorld>::SumStageStats() {
  stats_.ms_unconstrained = stats_.ms_stage_begin_steps;
  stats_.ms_rows += stats_.ms_stage_partners + stats_.ms_stage_islands +
                    stats_.ms_stage_couple_rigid + stats_.ms_stage_row_sources;
  stats_.ms_integrate = stats_.ms_stage_end_steps;
  stats_.rigid_bodies_coupled = static_cast<int>(coupled_.size());
}

template <class BulletWorld>
void DeformableWorldOf<BulletWorld>::BeginDeformableSteps(double h, int& begun) {
  UpdateKinematicAttachments();
  const Vec3 gravity = ToEigen(this->getGravity());
  const int num_bodies = static_cast<int>(bodies_.size());
  if (pool_ != nullptr && num_bodies >= 2 && !IsCholmodAvailable()) {
    // Safe in parallel: a body's BeginStep writes only that body (state, element model, system
    // and factor) and reads its rest data, immutable when shared. Not with CHOLMOD: its
    // factorization switches the process-wide OpenMP setting for the call.
    begun = num_bodies;  // every body's step runs, also past a failing one
    auto begin_step = [&](int b) { bodies_[b]->body().BeginStep(h, gravity); };
    pool_->Run(num_bodies, begin_step);
    return;
  }
  // One body at a time: the pool (if any) splits each body's element loops instead, bitwise the
  // same (plugin/element_loop_runner.h); lent for this stage only, where no pool task is running.
  for (auto& entry : bodies_) {
    ++begun;
    const LentLoopRunner lent(entry->body(), pool_.get());
    entry->body().BeginStep(h, gravity);
  }
}

template <class BulletWorld>
void DeformableWorldOf<BulletWorld>::FindContactPartners(double h) {
  // Rigid partners may move too: each body's reach grows by the fastest rigid motion this step.
  double max_rigid_speed = 0.0;
  const btCollisionObjectArray& objects = this->getCollisionObjectArray();
  for (int i = 0; i < objects.size(); ++i) {
    if (IslandBuilder::IsDynamicRigidBody(*objects[i]))
      max_rigid_speed = std::max(
          max_rigid_speed,
          static_cast<double>(btRigidBody::upcast(objects[i])->getLinearVelocity().length()));
    if (const auto* link = btMultiBodyLinkCollider::upcast(objects[i]))
      max_rigid_speed = std::max(max_rigid_speed, EstimateLinkSpeed(*link));
  }
  for (auto& entry : bodies_) {
    CalcSweptBounds(entry->body(), h, entry->body().settings().contact_margin, entry->swept_lo,
                    entry->swept_hi);
    FindRigidPartners(*entry, h * max_rigid_speed);
  }
  FindDeformablePairs();
}

template <class BulletWorld>
void DeformableWorldOf<BulletWorld>::FindRigidPartners(Entry& entry, double reach) {
  entry.partners.clear();
  const Vec3 lo = entry.swept_lo.array() - reach;
  const Vec3 hi = entry.swept_hi.array() + reach;
  btCollisionObjectArray& objects = this->getCollisionObjectArray();
  for (int i = 0; i < objects.size(); ++i) {
    btCollisionObject* object = objects[i];
    btCollisionShape* shape = object->getCollisionShape();
    if (shape->getShapeType() == kDeformableShapeType) continue;
    if (!object->hasContactResponse() || object->getBroadphaseHandle() == nullptr) continue;
    if (!ShouldCollide(entry.collision_object(), *object)) continue;  // groups and masks
    if (!Overlaps(lo, hi, *object->getBroadphaseHandle())) continue;
    PrepareNarrowphaseShape(*shape);
    // Static, kinematic and dynamic rigid objects and multibody links; the island body of a
    // dynamic one is set in CoupleRigidBodies, of a link's multibody in CoupleMultiBodies.
    if (IslandBuilder::IsDynamicRigidBody(*object) || object->isStaticOrKinematicObject()) {
      entry.partners.push_back({object, nullptr});
    } else if (const auto* link = btMultiBodyLinkCollider::upcast(object)) {
      if (link->m_multiBody != nullptr)
        entry.partners.push_back({object, nullptr, nullptr, link->m_link});
    }
  }
}

template <class BulletWorld>
void DeformableWorldOf<BulletWorld>::FindDeformablePairs() {
  active_pairs_.clear();
  // The pair's source is kept across steps for its warm starts.
  auto activate = [this](int d, int e) {
    PairContact& pair = pair_contacts_[{bodies_[d].get(), bodies_[e].get()}];
    if (pair.source == nullptr) {
      pair.source_id = next_source_id_++;
      pair.source = MakePairContactSource(*bodies_[d], *bodies_[e], pair.source_id);
    }
    active_pairs_.push_back({d, e, pair.source.get()});
  };
  const int num_deformables = static_cast<int>(bodies_.size());
  for (int d = 0; d < num_deformables; ++d) {
    // Self-contact (opt-in): the body as both sides, every step (its own spatial hash culls).
    if (bodies_[d]->body().settings().self_collision) activate(d, d);
    for (int e = d + 1; e < num_deformables; ++e) {
      const Entry& first = *bodies_[d];
      const Entry& second = *bodies_[e];
      if ((first.swept_lo.array() > second.swept_hi.array()).any() ||
          (second.swept_lo.array() > first.swept_hi.array()).any())
        continue;
      if (!ShouldCollide(first.object->collision_object(), second.object->collision_object()))
        continue;
      activate(d, e);
    }
  }
}

template <class BulletWorld>
std::unique_ptr<DeformableContactSource> DeformableWorldOf<BulletWorld>::MakePairContactSource(
    const Entry& first, const Entry& second, int source_id) const {
  const DeformableBodySettings& a = first.object->body().settings();
  const DeformableBodySettings& b = second.object->body().settings();
  if (&first == &second)  // self-contact: the body's boundary (not an embedded contact surface)
    return std::make_unique<DeformableContactSource>(
        first.object->body(), MakeBodyContactSurface(first.object->body().model()), source_id,
        a.friction * a.friction, a.contact_margin);
  return std::make_unique<DeformableContactSource>(
      first.object->body(), first.surface, second.object->body(), second.surface, source_id,
      a.friction * b.friction, std::max(a.contact_margin, b.contact_margin));
}

template <class BulletWorld>
void DeformableWorldOf<BulletWorld>::UniteIslands() {
  const int num_deformables = static_cast<int>(bodies_.size());
  islands_.Reset(num_deformables, this->getCollisionObjectArray());
  for (int d = 0; d < num_deformables; ++d) {
    const Entry& entry = *bodies_[d];
    for (const ContactPartner& partner : entry.partners) {
      const int index = islands_.DynamicIndex(*partner.object);
      if (index >= 0) islands_.Unite(d, index);
      const int multibody = islands_.MultiBodyIndex(*partner.object);
      if (multibody >= 0) islands_.Unite(d, multibody);
    }
    for (const auto& attachment : entry.dynamic_attachments) {
      const int index = islands_.DynamicIndex(*attachment->rigid()->rigid());
      if (index >= 0) islands_.Unite(d, index);
    }
  }
  for (const DeformablePair& pair : active_pairs_) islands_.Unite(pair.first, pair.second);
  islands_.UniteTouchingRigidBodies(*this->getDispatcher());
  islands_.UniteJointedRigidBodies(*this);
  islands_.MakeDeformableIslands(next_source_id_);
  for (int d = 0; d < num_deformables; ++d) {
    Entry& entry = *bodies_[d];
    entry.island = islands_.island_of_deformable(d);
    islands_.island(entry.island).bodies.push_back(entry.island_body.get());
  }
}

template <class BulletWorld>
void DeformableWorldOf<BulletWorld>::CoupleRigidBodies(double h) {
  coupled_.clear();
  const int first_dynamic = static_cast<int>(bodies_.size());
  for (int k = 0; k < islands_.num_dynamic_bodies(); ++k) {
    const int island = islands_.IslandOf(first_dynamic + k);
    if (island < 0) continue;  // a rigid-only island: Bullet's alone
    btRigidBody* rigid = islands_.dynamic_body(first_dynamic + k);
    RigidIslandBody* body = FindRigidIslandBody(rigid);
    rigid->activate();  // Bullet's sleeping test does not see deformable contacts
    body->BeginStep(h);
    coupled_.push_back(body);
    islands_.island(island).bodies.push_back(body);
  }
  for (auto& entry : bodies_)
    for (ContactPartner& partner : entry->partners) {
      const int index = islands_.DynamicIndex(*partner.object);
      if (index >= 0) partner.rigid = FindRigidIslandBody(islands_.dynamic_body(index));
    }
}

template <class BulletWorld>
void DeformableWorldOf<BulletWorld>::CoupleMultiBodies(double h) {
  // After Bullet's solve: v* is the velocity Bullet's multibody solver left (its joint motors,
  // limits and contacts with rigid objects), and W = M^-1 uses its articulated-body pass.
  for (int k = 0; k < islands_.num_multibodies(); ++k) {
    const int index = islands_.multibody_index(k);
    const int island = islands_.IslandOf(index);
    if (island < 0) continue;  // touches no deformable: Bullet's alone
    MultiBodyIslandBody* body = FindMultiBodyIslandBody(islands_.multibody(index));
    WakeMultiBody(*body->multibody());  // Bullet's sleeping test does not see deformable contacts
    body->BeginStep(h);
    coupled_multibodies_.push_back(body);
    islands_.island(island).bodies.push_back(body);
  }
  for (auto& entry : bodies_) {
    bool linked = false;
    for (ContactPartner& partner : entry->partners) {
      const int index = islands_.MultiBodyIndex(*partner.object);
      if (index < 0) continue;
      partner.multibody = FindMultiBodyIslandBody(islands_.multibody(index));
      linked = true;
    }
    // The contact source took its copy of the partners in GatherRowSources.
    if (linked) entry->contacts->set_partners(entry->partners);
  }
}

template <class BulletWorld>
void DeformableWorldOf<BulletWorld>::GatherMultiBodyMotors() {
  suspended_motors_.clear();
  if constexpr (std::is_base_of_v<btMultiBodyDynamicsWorld, BulletWorld>) {
    for (auto& source : motor_sources_)
      if (source != nullptr) source->Clear();
    for (int c = 0; c < this->getNumMultiBodyConstraints(); ++c) {
      auto* motor = dynamic_cast<btMultiBodyJointMotor*>(this->getMultiBodyConstraint(c));
      if (motor == nullptr || motor->getMaxAppliedImpulse() == btScalar(0)) continue;
      const int index = islands_.FindMultiBodyIndex(motor->getMultiBodyA());
      const int island = index >= 0 ? islands_.IslandOf(index) : -1;
      if (island < 0) continue;  // Bullet's alone
      if (static_cast<int>(motor_sources_.size()) <= island) motor_sources_.resize(island + 1);
      auto& source = motor_sources_[island];
      if (source == nullptr) source = std::make_unique<MultiBodyMotorSource>(next_source_id_++);
      source->AddMotor(*motor, FindMultiBodyIslandBody(motor->getMultiBodyA()), c);
      suspended_motors_.push_back({motor, motor->getMaxAppliedImpulse()});
    }
    for (size_t i = 0; i < motor_sources_.size() && static_cast<int>(i) < islands_.num_islands();
         ++i)
      if (motor_sources_[i] != nullptr && motor_sources_[i]->num_motors() > 0)
        islands_.island(static_cast<int>(i)).sources.push_back(motor_sources_[i].get());
  }
}

template <class BulletWorld>
void DeformableWorldOf<BulletWorld>::SuspendMotors() {
  for (auto& [motor, impulse] : suspended_motors_) motor->setMaxAppliedImpulse(btScalar(0));
}

template <class BulletWorld>
void DeformableWorldOf<BulletWorld>::ResumeMotors() {
  for (auto& [motor, impulse] : suspended_motors_) motor->setMaxAppliedImpulse(impulse);
}

template <class BulletWorld>
MultiBodyIslandBody* DeformableWorldOf<BulletWorld>::FindMultiBodyIslandBody(btMultiBody* body) {
  auto& slot = multibody_bodies_[body];
  if (slot == nullptr) slot = std::make_unique<MultiBodyIslandBody>(body);
  return slot.get();
}

template <class BulletWorld>
RigidIslandBody* DeformableWorldOf<BulletWorld>::FindCoupledBody(const btCollisionObject& object,
                                                                 int& island) {
  const int index = islands_.DynamicIndex(object);
  if (index < 0) return nullptr;
  const int coupled_island = islands_.IslandOf(index);
  if (coupled_island < 0) return nullptr;
  island = coupled_island;
  return FindRigidIslandBody(islands_.dynamic_body(index));
}

template <class BulletWorld>
void DeformableWorldOf<BulletWorld>::GatherRowSources(const btContactSolverInfo& info) {
  AddCoupledManifoldsAndJoints(info);
  for (auto& entry : bodies_) {
    Island& island = islands_.island(entry->island);
    for (auto& source : entry->sources) island.sources.push_back(source.get());
    if (!entry->partners.empty()) {
      entry->contacts->set_partners(entry->partners);
      entry->contacts->set_restitution_threshold(info.m_restitutionVelocityThreshold);
      island.sources.push_back(entry->contacts.get());
    }
    for (auto& attachment : entry->dynamic_attachments) island.sources.push_back(attachment.get());
  }
  for (const DeformablePair& pair : active_pairs_)
    islands_.island(bodies_[pair.first]->island).sources.push_back(pair.source);
  GatherMultiBodyMotors();
  for (int i = 0; i < islands_.num_islands(); ++i) {
    Island& island = islands_.island(i);
    if (island.manifolds->num_points() > 0) island.sources.push_back(island.manifolds.get());
    if (island.joints->num_rows() > 0) island.sources.push_back(island.joints.get());
  }
}

template <class BulletWorld>
void DeformableWorldOf<BulletWorld>::AddCoupledManifoldsAndJoints(const btContactSolverInfo& info) {
  btDispatcher* dispatcher = this->getDispatcher();
  for (int m = 0; m < dispatcher->getNumManifolds(); ++m) {
    const btPersistentManifold* manifold = dispatcher->getManifoldByIndexInternal(m);
    if (manifold->getNumContacts() == 0) continue;
    int island = -1;
    const RigidIslandBody* a = FindCoupledBody(*manifold->getBody0(), island);
    const RigidIslandBody* b = FindCoupledBody(*manifold->getBody1(), island);
    if (island >= 0) islands_.island(island).manifolds->AddManifold(*manifold, a, b, info);
  }
  for (int j = 0; j < this->getNumConstraints(); ++j) {
    btTypedConstraint* joint = this->getConstraint(j);
    int island = -1;
    const RigidIslandBody* a = FindCoupledBody(joint->getRigidBodyA(), island);
    const RigidIslandBody* b = FindCoupledBody(joint->getRigidBodyB(), island);
    if (island >= 0) islands_.island(island).joints->AddJoint(*joint, a, b, info);
  }
}

template <class BulletWorld>
void DeformableWorldOf<BulletWorld>::SolveRigidIslandsWithBullet(btContactSolverInfo& info) {
  // Bullet's solver runs on every rigid body, the coupled ones too, although their answer is
  // replaced (EndSteps restores their transform and writes the island's velocity). Its pass over
  // them must stay: it is what breaks a joint whose impulse exceeds its breaking threshold
  // (JointSource only bounds the multiplier by it), and it writes the manifold points' impulses
  // and friction directions and the joints' applied impulses, which Bullet warm-starts from once
  // the bodies are back in a rigid-only island and which users read. Leaving the coupled bodies
  // out (an island callback that skips them) keeps the determinism pins, but a breakable joint on
  // a box resting on a soft block then never breaks, and the run diverges.
  BulletWorld::solveConstraints(info);
}

namespace {
// True when `shape` is or holds a GImpact shape, whose triangle queries lock it (they write it).
bool HasGImpactShape(const btCollisionShape& shape) {
  if (shape.getShapeType() == GIMPACT_SHAPE_PROXYTYPE) return true;
  if (shape.getShapeType() != COMPOUND_SHAPE_PROXYTYPE) return false;
  const auto& compound = static_cast<const btCompoundShape&>(shape);
  for (int i = 0; i < compound.getNumChildShapes(); ++i)
    if (HasGImpactShape(*compound.getChildShape(i))) return true;
  return false;
}
}  // namespace

template <class BulletWorld>
bool DeformableWorldOf<BulletWorld>::CanSolveIslandsInParallel() const {
  if (pool_ == nullptr || solved_islands_.size() < 2) return false;
  for (const auto& entry : bodies_) {
    if (entry->object->body().system().uses_cholmod()) return false;  // see BeginDeformableSteps
    for (const ContactPartner& partner : entry->partners)
      if (HasGImpactShape(*partner.object->getCollisionShape())) return false;
  }
  return true;
}

template <class BulletWorld>
void DeformableWorldOf<BulletWorld>::SolveIslands(double h) {
  solved_islands_.clear();
  for (int i = 0; i < islands_.num_islands(); ++i)
    if (!islands_.island(i).sources.empty()) solved_islands_.push_back(i);
  const int num_solved = static_cast<int>(solved_islands_.size());
  island_stats_.assign(num_solved, StepStats());
  island_done_.assign(num_solved, 0);
  auto solve = [&](int k) {
    Island& island = islands_.island(solved_islands_[k]);
    bodies_[island.first_deformable]->solver.Solve(h, island.bodies, island.sources,
                                                   solver_settings_, island_stats_[k]);
    island_done_[k] = 1;
  };
  // In island order, up to the first island whose solve threw (as a loop over them would).
  auto merge_stats = [&] {
    for (int k = 0; k < num_solved && island_done_[k]; ++k) {
      AddIslandStats(island_stats_[k], stats_);
      stats_.islands++;
    }
  };
  try {
    if (CanSolveIslandsInParallel()) {
      // Safe in parallel: islands share no deformable and no dynamic rigid body (union-find), and
      // each has its own solver and sources, whose caches and scratch are theirs. Shared are
      // only read: static and kinematic partners (transform, shape, friction), rest meshes and
      // the settings. Bullet's queries from the sources (btGjkEpaSolver2, support mappings,
      // concave triangle queries) keep their state on the stack; GImpact shapes, which lock
      // themselves, and CHOLMOD keep the step serial (CanSolveIslandsInParallel).
      pool_->Run(num_solved, solve);
    } else {
      for (int k = 0; k < num_solved; ++k) solve(k);
    }
  } catch (...) {
    merge_stats();
    throw;
  }
  merge_stats();
}

template <class BulletWorld>
void DeformableWorldOf<BulletWorld>::EndSteps(double h) {
  for (auto& entry : bodies_) entry->body().EndStep(h);
  for (RigidIslandBody* rigid : coupled_) rigid->EndStep();
  for (MultiBodyIslandBody* multibody : coupled_multibodies_) multibody->EndStep();
}

template <class BulletWorld>
void DeformableWorldOf<BulletWorld>::ReportForces() {
  for (int i = 0; i < islands_.num_islands(); ++i) {
    const Island& island = islands_.island(i);
    if (island.sources.empty()) continue;  // not solved this substep
    const IslandSolver& solver = bodies_[island.first_deformable]->solver;
    AppendIslandForces(island.bodies, solver.last_rows(), solver.last_multipliers(),
                       this->getCollisionObjectArray(), forces_);
  }
}

namespace {
// The entries of `all` (contacts or limit rows of the last substep) that belong to `body`.
template <typename Entry>
std::vector<Entry> SelectBodyEntries(const std::vector<Entry>& all, const DeformableBody* body) {
  std::vector<Entry> selected;
  for (const Entry& entry : all)
    if (entry.body == body) selected.push_back(entry);
  return selected;
}
}  // namespace

template <class BulletWorld>
std::vector<typename DeformableWorldOf<BulletWorld>::SolvedIsland>
DeformableWorldOf<BulletWorld>::last_solved_islands() const {
  std::vector<SolvedIsland> solved;
  if (!islands_solved_) return solved;
  for (int i = 0; i < islands_.num_islands(); ++i) {
    const Island& island = islands_.island(i);
    if (island.sources.empty()) continue;  // not solved this substep
    const IslandSolver& solver = bodies_[island.first_deformable]->solver;
    solved.push_back({&island.bodies, &solver.last_rows(), &solver.last_multipliers()});
  }
  return solved;
}

template <class BulletWorld>
std::vector<int> DeformableWorldOf<BulletWorld>::driven_nodes(const DeformableBody* body,
                                                              const btRigidBody* rigid) const {
  TAUT_DEMAND(HasBody(body), "driven_nodes: deformable body is not in this world");
  std::vector<int> nodes;
  for (const auto& entry : bodies_) {
    if (&entry->object->body() != body) continue;
    for (const typename Entry::Attachment& attachment : entry->attachments)
      if (attachment.rigid == rigid)
        nodes.insert(nodes.end(), attachment.nodes.begin(), attachment.nodes.end());
  }
  return nodes;
}

template <class BulletWorld>
std::vector<DeformableContactPoint> DeformableWorldOf<BulletWorld>::last_contacts(
    const DeformableBody* body) const {
  TAUT_DEMAND(HasBody(body), "last_contacts: deformable body is not in this world");
  return SelectBodyEntries(forces_.contacts, body);
}

template <class BulletWorld>
std::vector<LimitRowMultiplier> DeformableWorldOf<BulletWorld>::last_limit_multipliers(
    const DeformableBody* body) const {
  TAUT_DEMAND(HasBody(body), "last_limit_multipliers: deformable body is not in this world");
  return SelectBodyEntries(forces_.limits, body);
}

template <class BulletWorld>
bool DeformableWorldOf<BulletWorld>::HasBody(const DeformableBody* body) const {
  return std::any_of(bodies_.begin(), bodies_.end(),
                     [body](const auto& entry) { return &entry->object->body() == body; });
}

template <class BulletWorld>
void DeformableWorldOf<BulletWorld>::solveConstraints(btContactSolverInfo& info) {
  const double h = static_cast<double>(info.m_timeStep);
  forces_.Clear(h);
  islands_solved_ = false;
  if (bodies_.empty()) {
    BulletWorld::solveConstraints(info);
    return;
  }
  stats_ = StepStats();
  coupled_.clear();
  coupled_multibodies_.clear();
  int begun = 0;
  try {
    StepDeformables(h, info, begun);
  } catch (const SimulationError&) {
    // A body failed (it restored itself): every other body goes back to the step start too, so
    // the world stays consistent at the last good state.
    for (int b = 0; b < begun; ++b) bodies_[b]->body().AbortStep();
    for (RigidIslandBody* rigid : coupled_) rigid->AbortStep();
    for (MultiBodyIslandBody* multibody : coupled_multibodies_) multibody->AbortStep();
    forces_.Clear(h);
    throw;
  }
}

template class DeformableWorldOf<btDiscreteDynamicsWorld>;
template class DeformableWorldOf<btMultiBodyDynamicsWorld>;

}  // namespace taut
