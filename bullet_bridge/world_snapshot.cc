// DeformableWorld::SaveSnapshot and RestoreSnapshot (bullet_bridge/world_snapshot.h).
#include "bullet_bridge/world_snapshot.h"

#include <algorithm>
#include <unordered_map>

#include "bullet_bridge/deformable_world.h"
namespace taut {
// The stages of a snapshot, with access to the world's entries.
template <class BulletWorld>
struct DeformableWorldOf<BulletWorld>::Snapshots {
  // Each body's state and its solver's warm starts.
  static void SaveDeformables(const DeformableWorldOf& world, WorldSnapshot& snapshot);
  // The row-key source ids the world hands out as it steps: deformable pairs and island slots.
  static void SaveSourceIds(const DeformableWorldOf& world, WorldSnapshot& snapshot);
  // Forces out with pointers as indices.
  static void SaveForces(const DeformableWorldOf& world, WorldSnapshot& snapshot);
  // Throws InputError unless the snapshot's deformables fit the world's.
  static void CheckDeformables(const DeformableWorldOf& world, const WorldSnapshot& snapshot);
  static void RestoreDeformables(DeformableWorldOf& world, const WorldSnapshot& snapshot);
  static void RestoreSourceIds(DeformableWorldOf& world, const WorldSnapshot& snapshot);
  static void RestoreForces(DeformableWorldOf& world, const WorldSnapshot& snapshot);
  // The id counter after a restore (see the definition).
  static int CalcRestoredNextSourceId(const DeformableWorldOf& world,
                                      const WorldSnapshot& snapshot);
};

namespace {
// Index of each element of `items` by pointer (the inverse of the world's lists).
template <typename Pointer>
std::unordered_map<const void*, int> IndexByPointer(const std::vector<Pointer>& items) {
  std::unordered_map<const void*, int> index;
  for (size_t i = 0; i < items.size(); ++i) index[items[i]] = static_cast<int>(i);
  return index;
}

// The index of `pointer` in `index`, -1 for null or unknown.
int FindIndex(const std::unordered_map<const void*, int>& index, const void* pointer) {
  const auto it = index.find(pointer);
  return it == index.end() ? -1 : it->second;
}

// Number of free nodes of `kinds`.
int CountFreeNodes(const std::vector<NodeKind>& kinds) {
  return static_cast<int>(std::count(kinds.begin(), kinds.end(), NodeKind::kFree));
}
}  // namespace

template <class BulletWorld>
void DeformableWorldOf<BulletWorld>::Snapshots::SaveDeformables(const DeformableWorldOf& world,
                                                                WorldSnapshot& snapshot) {
  snapshot.deformables.resize(world.bodies_.size());
  for (size_t b = 0; b < world.bodies_.size(); ++b) {
    const Entry& entry = *world.bodies_[b];
    WorldSnapshot::Deformable& saved = snapshot.deformables[b];
    saved.num_elements = entry.object->body().num_elements();
    entry.object->body().SaveState(saved.body);
    entry.solver.SaveState(saved.solver);
  }
}

template <class BulletWorld>
void DeformableWorldOf<BulletWorld>::Snapshots::SaveSourceIds(const DeformableWorldOf& world,
                                                              WorldSnapshot& snapshot) {
  std::vector<const Entry*> entries;
  for (const auto& entry : world.bodies_) entries.push_back(entry.get());
  const auto index = IndexByPointer(entries);
  snapshot.pair_contacts.clear();
  for (const auto& [key, pair] : world.pair_contacts_)
    snapshot.pair_contacts.push_back(
        {FindIndex(index, key.first), FindIndex(index, key.second), pair.source_id});
  snapshot.island_source_ids = world.islands_.SaveSourceIds();
  snapshot.next_source_id = world.next_source_id_;
}

template <class BulletWorld>
void DeformableWorldOf<BulletWorld>::Snapshots::SaveForces(const DeformableWorldOf& world,
                                                           WorldSnapshot& snapshot) {
  std::vector<const DeformableBody*> bodies;
  for (const auto& entry : world.bodies_) bodies.push_back(&entry->object->body());
  std::vector<const btCollisionObject*> objects;
  for (int i = 0; i < world.getNumCollisionObjects(); ++i)
    objects.push_back(world.getCollisionObjectArray()[i]);
  const auto body_index = IndexByPointer(bodies);
  const auto object_index = IndexByPointer(objects);
  WorldSnapshot::Forces& forces = snapshot.forces;
  forces.values = world.forces_;
  forces.contacts.clear();
  forces.wrenches.clear();
  forces.limits.clear();
  for (DeformableContactPoint& contact : forces.values.contacts) {
    forces.contacts.push_back({FindIndex(body_index, contact.body),
                               FindIndex(body_index, contact.partner_body),
                               FindIndex(object_index, contact.partner_object)});
    contact.body = contact.partner_body = nullptr;
    contact.partner_object = nullptr;
  }
  for (RigidBodyWrench& wrench : forces.values.wrenches) {
    forces.wrenches.push_back(FindIndex(object_index, wrench.object));
    wrench.object = nullptr;
    wrench.rigid = nullptr;
  }
  for (LimitRowMultiplier& limit : forces.values.limits) {
    forces.limits.push_back(FindIndex(body_index, limit.body));
    limit.body = nullptr;
  }
}

template <class BulletWorld>
void DeformableWorldOf<BulletWorld>::Snapshots::CheckDeformables(const DeformableWorldOf& world,
                                                                 const WorldSnapshot& snapshot) {
  TAUT_DEMAND(snapshot.deformables.size() == world.bodies_.size(),
              "RestoreSnapshot: the world has ", world.bodies_.size(),
              " deformable bodies, the snapshot ", snapshot.deformables.size());
  for (size_t b = 0; b < world.bodies_.size(); ++b) {
    const DeformableBody& body = world.bodies_[b]->object->body();
    const WorldSnapshot::Deformable& saved = snapshot.deformables[b];
    const int saved_nodes = static_cast<int>(saved.body.kinds.size());
    TAUT_DEMAND(saved_nodes == body.num_nodes() && saved.num_elements == body.num_elements(),
                "RestoreSnapshot: deformable body ", b, " ('", body.name(), "') has ",
                body.num_nodes(), " nodes and ", body.num_elements(), " elements, in the snapshot ",
                saved_nodes, " nodes and ", saved.num_elements, " elements");
    const ImplicitSystem::NewtonState& newton = saved.body.newton;
    TAUT_DEMAND(!newton.analyzed || newton.H.rows() == 3 * CountFreeNodes(saved.body.kinds),
                "RestoreSnapshot: deformable body ", b, " ('", body.name(),
                "'): the snapshot's Newton matrix does not fit its node kinds");
  }
  for (const WorldSnapshot::PairContact& pair : snapshot.pair_contacts)
    TAUT_DEMAND(pair.first >= 0 && pair.first < pair.second &&
                    pair.second < static_cast<int>(world.bodies_.size()),
                "RestoreSnapshot: the snapshot's deformable pair (", pair.first, ", ", pair.second,
                ") is not a pair of this world's ", world.bodies_.size(), " deformable bodies");
}

template <class BulletWorld>
void DeformableWorldOf<BulletWorld>::Snapshots::RestoreDeformables(DeformableWorldOf& world,
                                                                   const WorldSnapshot& snapshot) {
  for (size_t b = 0; b < world.bodies_.size(); ++b) {
    Entry& entry = *world.bodies_[b];
    entry.object->body().RestoreState(snapshot.deformables[b].body);
    entry.solver.RestoreState(snapshot.deformables[b].solver);
  }
}

// Sources the world makes as it steps (deformable pairs, island slots) take their id from the
// counter. The restore puts the saved ones back, so the saved counter is safe when every id
// handed out since the snapshot went to such a source: then a world reset again and again reuses
// the same ids (keys stay below 2^16). Any other id handed out since (a limit or an attachment
// added after the snapshot) keeps the current counter, so ids stay unique.
template <class BulletWorld>
int DeformableWorldOf<BulletWorld>::Snapshots::CalcRestoredNextSourceId(
    const DeformableWorldOf& world, const WorldSnapshot& snapshot) {
  const int saved = snapshot.next_source_id;
  const int current = world.next_source_id_;
  if (current <= saved) return saved;
  int replaced = 0;  // ids >= saved held by sources the restore replaces
  for (const auto& [key, pair] : world.pair_contacts_) replaced += pair.source_id >= saved;
  for (const std::array<int, 2>& ids : world.islands_.SaveSourceIds())
    replaced += (ids[0] >= saved) + (ids[1] >= saved);
  return replaced == current - saved ? saved : current;
}

template <class BulletWorld>
void DeformableWorldOf<BulletWorld>::Snapshots::RestoreSourceIds(DeformableWorldOf& world,
                                                                 const WorldSnapshot& snapshot) {
  const int next_source_id = CalcRestoredNextSourceId(world, snapshot);
  // Pair sources: the saved ones with their ids, no others.
  decltype(world.pair_contacts_) pairs;
  for (const WorldSnapshot::PairContact& saved : snapshot.pair_contacts) {
    const Entry* first = world.bodies_[saved.first].get();
    const Entry* second = world.bodies_[saved.second].get();
    auto it = world.pair_contacts_.find({first, second});
    PairContact& pair = pairs[{first, second}];
    if (it != world.pair_contacts_.end() && it->second.source_id == saved.source_id) {
      pair = std::move(it->second);
      continue;
    }
    pair.source_id = saved.source_id;
    pair.source = world.MakePairContactSource(*first, *second, saved.source_id);
  }
  world.pair_contacts_ = std::move(pairs);
  world.active_pairs_.clear();  // this step's, pointing into the old map
  world.islands_.RestoreSourceIds(snapshot.island_source_ids);
  world.next_source_id_ = next_source_id;
}

template <class BulletWorld>
void DeformableWorldOf<BulletWorld>::Snapshots::RestoreForces(DeformableWorldOf& world,
                                                              const WorldSnapshot& snapshot) {
  const WorldSnapshot::Forces& saved = snapshot.forces;
  auto body = [&world](int b) -> const DeformableBody* {
    return b >= 0 ? &world.bodies_[b]->object->body() : nullptr;
  };
  auto object = [&world](int i) -> const btCollisionObject* {
    return i >= 0 ? world.getCollisionObjectArray()[i] : nullptr;
  };
  SubstepForces& forces = world.forces_;
  forces = saved.values;
  for (size_t c = 0; c < forces.contacts.size(); ++c) {
    forces.contacts[c].body = body(saved.contacts[c][0]);
    forces.contacts[c].partner_body = body(saved.contacts[c][1]);
    forces.contacts[c].partner_object = object(saved.contacts[c][2]);
  }
  for (size_t w = 0; w < forces.wrenches.size(); ++w) {
    forces.wrenches[w].object = object(saved.wrenches[w]);
    forces.wrenches[w].rigid = btRigidBody::upcast(object(saved.wrenches[w]));
  }
  for (size_t l = 0; l < forces.limits.size(); ++l) forces.limits[l].body = body(saved.limits[l]);
}

template <class BulletWorld>
WorldSnapshot DeformableWorldOf<BulletWorld>::SaveSnapshot() const {
  WorldSnapshot snapshot;
  SaveSnapshot(snapshot);
  return snapshot;
}

template <class BulletWorld>
void DeformableWorldOf<BulletWorld>::SaveSnapshot(WorldSnapshot& snapshot) const {
  Snapshots::SaveDeformables(*this, snapshot);
  Snapshots::SaveSourceIds(*this, snapshot);
  snapshot.bullet = SaveBulletWorldState(*this);
  snapshot.local_time = this->m_localTime;
  snapshot.fixed_time_step = this->m_fixedTimeStep;
  snapshot.last_step_stats = stats_;
  snapshot.last_call_stats = call_stats_;
  Snapshots::SaveForces(*this, snapshot);
}

template <class BulletWorld>
void DeformableWorldOf<BulletWorld>::RestoreSnapshot(const WorldSnapshot& snapshot) {
  Snapshots::CheckDeformables(*this, snapshot);
  CheckBulletWorldState(snapshot.bullet, *this);
  Snapshots::RestoreDeformables(*this, snapshot);
  Snapshots::RestoreSourceIds(*this, snapshot);
  // After the deformables: Bullet's collision detection may run, and sees their restored bounds.
  RestoreBulletWorldState(snapshot.bullet, *this);
  this->m_localTime = snapshot.local_time;
  this->m_fixedTimeStep = snapshot.fixed_time_step;
  stats_ = snapshot.last_step_stats;
  call_stats_ = snapshot.last_call_stats;
  Snapshots::RestoreForces(*this, snapshot);
}

template WorldSnapshot DeformableWorldOf<btDiscreteDynamicsWorld>::SaveSnapshot() const;
template void DeformableWorldOf<btDiscreteDynamicsWorld>::SaveSnapshot(WorldSnapshot&) const;
template void DeformableWorldOf<btDiscreteDynamicsWorld>::RestoreSnapshot(const WorldSnapshot&);
template WorldSnapshot DeformableWorldOf<btMultiBodyDynamicsWorld>::SaveSnapshot() const;
template void DeformableWorldOf<btMultiBodyDynamicsWorld>::SaveSnapshot(WorldSnapshot&) const;
template void DeformableWorldOf<btMultiBodyDynamicsWorld>::RestoreSnapshot(const WorldSnapshot&);

}  // namespace taut
