// Warm-start row keys (constraints/row_key.h, constraints/row_key_layouts.h): every field is
// checked against its width, keys round-trip, keys of different sources never collide, and the
// objects, ids and rows that the hand-packed layouts used to alias get different keys.
#include <btBulletDynamicsCommon.h>
#include <gtest/gtest.h>

#include <iterator>
#include <map>
#include <set>
#include <string>

#include "bullet_bridge/joint_source.h"
#include "bullet_bridge/node_attachment_source.h"
#include "bullet_bridge/rigid_contact_source.h"
#include "bullet_bridge/rigid_manifold_source.h"
#include "constraints/deformable_contact_source.h"
#include "constraints/deformable_island_body.h"
#include "constraints/energy_limit_source.h"
#include "constraints/node_height_source.h"
#include "constraints/row_key_layouts.h"
#include "constraints/strain_limit_source.h"
#include "plugin/box_tet_mesher.h"

namespace taut {
namespace {

constexpr double kH = 0.01;

// Calls f(layout) for the layout of every row source.
template <typename F>
void ForEachLayout(F&& f) {
  f(kStrainLimitRowKey);
  f(kEnergyLimitRowKey);
  f(kDeformableContactRowKey);
  f(kRigidContactRowKey);
  f(kRigidManifoldRowKey);
  f(kJointRowKey);
  f(kNodeAttachmentRowKey);
  f(kNodeHeightRowKey);
}

// The largest value of a field.
std::int64_t MaxValue(const RowKeyField& field) { return (std::int64_t{1} << field.bits) - 1; }

// Runs fn, expecting InputError whose message holds every part.
template <typename Fn>
void ExpectInputError(Fn&& fn, const std::vector<std::string>& parts) {
  try {
    fn();
    ADD_FAILURE() << "no InputError; expected one naming " << parts[0];
  } catch (const InputError& e) {
    for (const std::string& part : parts)
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos)
          << "'" << e.what() << "' lacks '" << part << "'";
  }
}

// A free 0.2 m tet cube with its step begun.
std::unique_ptr<DeformableBody> MakeCube(const Vec3& corner) {
  DeformableBodySettings settings;
  settings.name = "cube";
  settings.material = {1e5, 0.3, 1000.0};
  auto mesh = std::make_shared<const TetMesh>(MakeBoxTetMesh(Vec3(0.2, 0.2, 0.2), 1, 1, 1, corner));
  auto body = std::make_unique<DeformableBody>(
      std::make_unique<TetElementModel>(mesh, settings.material), settings);
  body->BeginStep(kH, Vec3::Zero());
  return body;
}

// The rows of `source` at zero velocity of every body.
std::vector<ConstraintRow> CollectRows(ConstraintSource& source,
                                       const std::vector<IslandBody*>& bodies) {
  std::vector<VecX> v, x(bodies.size());
  for (IslandBody* body : bodies) v.push_back(VecX::Zero(3 * body->num_blocks()));
  for (size_t b = 0; b < bodies.size(); ++b) bodies[b]->CalcPositions(kH, v[b], x[b]);
  std::vector<ConstraintRow> rows;
  source.AppendIslandRows(IslandIterate(kH, bodies, v, x), rows);
  return rows;
}

// How many keys of `rows` are shared with an earlier row.
int CountRepeatedKeys(const std::vector<ConstraintRow>& rows) {
  std::set<std::uint64_t> keys;
  int repeated = 0;
  for (const ConstraintRow& row : rows) repeated += keys.insert(row.key).second ? 0 : 1;
  return repeated;
}

TEST(RowKeyTest, EveryLayoutFitsBelowTheSourceId) {
  ForEachLayout([](const auto& layout) {
    EXPECT_LE(layout.bits(), kRowKeyPayloadBits) << layout.source;
    for (const RowKeyField& field : layout.fields) EXPECT_GE(field.bits, 1) << field.name;
  });
}

TEST(RowKeyTest, PackedFieldsRoundTripAtZeroMiddleAndLargestValues) {
  ForEachLayout([](const auto& layout) {
    constexpr std::size_t N = std::tuple_size<decltype(layout.fields)>::value;
    for (const int source_id : {0, 1, 4097, 65535}) {
      const RowKeyPacker<N> packer(layout, source_id);
      for (const int pattern : {0, 1, 2}) {
        std::array<std::int64_t, N> values{};
        for (std::size_t f = 0; f < N; ++f) {
          const std::int64_t max = MaxValue(layout.fields[f]);
          const std::int64_t middle = max / 2 + static_cast<std::int64_t>(f % 2);
          values[f] = pattern == 0 ? 0 : pattern == 1 ? middle : max;
        }
        const std::uint64_t key = packer.PackFields(values);
        EXPECT_EQ(packer.Unpack(key), values) << layout.source;
        EXPECT_EQ(RowKeySource(key), source_id) << layout.source;
        EXPECT_TRUE(packer.Owns(key));
        EXPECT_EQ(UnpackRowKeyPayload(layout, RowKeyPayload(key)), values);
      }
    }
  });
}

TEST(RowKeyTest, EachFieldThatOverflowsItsWidthThrowsNamingTheFieldValueAndWidth) {
  ForEachLayout([](const auto& layout) {
    constexpr std::size_t N = std::tuple_size<decltype(layout.fields)>::value;
    const RowKeyPacker<N> packer(layout, 3);
    for (std::size_t f = 0; f < N; ++f) {
      const RowKeyField& field = layout.fields[f];
      for (const std::int64_t bad : {MaxValue(field) + 1, std::int64_t{-1}}) {
        std::array<std::int64_t, N> values{};
        values[f] = bad;
        ExpectInputError([&] { packer.PackFields(values); },
                         {layout.source, std::string(field.name) + " " + std::to_string(bad),
                          std::to_string(field.bits) + "-bit"});
      }
      std::array<std::int64_t, N> largest{};
      largest[f] = MaxValue(field);
      EXPECT_NO_THROW(packer.PackFields(largest)) << field.name;
    }
  });
  // Unsigned indices beyond int64 are reported, not wrapped.
  const RowKeyPacker<2> joints(kJointRowKey, 0);
  ExpectInputError([&] { joints.Pack(0, ~std::size_t{0}); }, {"joints", "row", "17-bit"});
}

TEST(RowKeyTest, SourceIdBeyond16BitsThrowsInEveryPackerAndEverySourceConstructor) {
  ForEachLayout([](const auto& layout) {
    constexpr std::size_t N = std::tuple_size<decltype(layout.fields)>::value;
    for (const int bad : {1 << 16, -1})
      ExpectInputError([&] { (void)RowKeyPacker<N>(layout, bad); },
                       {layout.source, "source id " + std::to_string(bad), "16-bit"});
    EXPECT_NO_THROW((void)RowKeyPacker<N>(layout, (1 << 16) - 1));
  });
  std::unique_ptr<DeformableBody> a = MakeCube(Vec3::Zero()), b = MakeCube(Vec3(0, 0, 0.3));
  const TetMesh& mesh = static_cast<const TetElementModel&>(a->model()).mesh();
  const ContactSurface surface = MakeTetContactSurface(mesh);
  btSphereShape shape(0.05);
  btRigidBody rigid(1.0, nullptr, &shape, btVector3(1, 1, 1));
  RigidIslandBody bone(&rigid);
  for (const int bad : {1 << 16, -1}) {
    const std::string id = "source id " + std::to_string(bad);
    ExpectInputError([&] { StrainLimitSource(*a, StrainLimitSettings::Isotropic(0.9, 1.1), bad); },
                     {"strain limits", id});
    ExpectInputError(
        [&] { EnergyLimitSource(*a, EnergyLimitSettings::PerElementEnergy(1.0), bad); },
        {"energy limits", id});
    ExpectInputError([&] { DeformableContactSource(*a, surface, *b, surface, bad, 0.5, 0.01); },
                     {"deformable contact", id});
    ExpectInputError([&] { RigidContactSource(*a, surface, bad, 0.5, 0.01); },
                     {"rigid contact", id});
    ExpectInputError([&] { RigidManifoldSource source(bad); }, {"rigid manifold", id});
    ExpectInputError([&] { JointSource source(bad); }, {"joints", id});
    ExpectInputError([&] { NodeAttachmentSource(*a, &bone, {0}, {Vec3::Zero()}, bad); },
                     {"node attachment", id});
    ExpectInputError([&] { NodeHeightSource(*a, 0.0, 0.01, bad); }, {"node height", id});
  }
}

TEST(RowKeyTest, KeysOfDifferentSourcesNeverCollideOnAnEnumeratedSet) {
  // Each source of a world has its own id; values near the old layouts' strides included.
  std::map<std::uint64_t, std::string> seen;
  int source_id = 0, count = 0;
  ForEachLayout([&](const auto& layout) {
    constexpr std::size_t N = std::tuple_size<decltype(layout.fields)>::value;
    const RowKeyPacker<N> packer(layout, source_id++);
    const std::int64_t candidates[] = {0, 1, 2, 3, 256, 4096, 4097, 65536, 1 << 20};
    std::array<int, N> digit{};  // odometer over the candidates, per field
    while (true) {
      std::array<std::int64_t, N> values{};
      bool fits = true;
      for (std::size_t f = 0; f < N; ++f) {
        values[f] = candidates[digit[f]];
        fits = fits && values[f] <= MaxValue(layout.fields[f]);
      }
      if (fits) {
        std::string name = layout.source;
        for (std::int64_t v : values) name += " " + std::to_string(v);
        const auto [it, inserted] = seen.emplace(packer.PackFields(values), name);
        EXPECT_TRUE(inserted) << name << " collides with " << it->second;
        ++count;
      }
      std::size_t f = 0;
      while (f < N && ++digit[f] == static_cast<int>(std::size(candidates))) digit[f++] = 0;
      if (f == N) break;
    }
  });
  EXPECT_GT(count, 1000);
}

TEST(RowKeyTest, StrainLimitKeyPacksWithTheSharedLayout) {
  const StrainLimitKey key{123456, 2, 1, StrainBound::kMin};
  EXPECT_EQ(key.Pack(), PackRowKeyPayload(kStrainLimitRowKey, key.Fields()));
  EXPECT_TRUE(StrainLimitKey::Unpack(key.Pack()) == key);
  const RowKeyPacker<4> packer(kStrainLimitRowKey, 9);
  EXPECT_TRUE(StrainLimitKey::Unpack(RowKeyPayload(packer.PackFields(key.Fields()))) == key);
  ExpectInputError([] { StrainLimitKey{}.Pack(); }, {"strain limits", "element -1"});
}

TEST(RowKeyTest, EnergyKeysStayTheSourceIdAboveTheElement) {
  const RowKeyPacker<1> packer(kEnergyLimitRowKey, 5);
  EXPECT_EQ(packer.Pack(17), (std::uint64_t{5} << 48) | 17u);
}

// Two static boxes under the cube, in the same place: every bottom point touches both. Their
// world indices differ by 4096 (the old layout kept 12 bits) or by 65536; objects in no world
// (index -1) are told apart by their position among the partners.
TEST(RowKeyTest, RigidObjectsWhoseWorldIndicesDifferBy4096Or65536GetDifferentKeys) {
  std::unique_ptr<DeformableBody> cube = MakeCube(Vec3(-0.1, -0.1, 0.0));
  btBoxShape shape(btVector3(0.3, 0.3, 0.05));
  btCollisionObject near, far;
  for (btCollisionObject* object : {&near, &far}) {
    object->setCollisionShape(&shape);
    object->setWorldTransform(btTransform(btQuaternion::getIdentity(), btVector3(0, 0, -0.05)));
  }
  RigidContactSource source(*cube, MakeBodyContactSurface(cube->model()), 1, 0.5, 0.01);
  source.set_objects({&near, &far});
  DeformableIslandBody body(*cube);
  const std::pair<int, int> indices[] = {{3, 3 + 4096}, {3, 3 + 65536}, {0, 1 << 20},
                                         {-1, -1},      {-1, 0},        {1, -1}};
  for (const auto& [near_index, far_index] : indices) {
    near.setWorldArrayIndex(near_index);
    far.setWorldArrayIndex(far_index);
    const std::vector<ConstraintRow> rows = CollectRows(source, {&body});
    ASSERT_GE(rows.size(), 2u * 4 * 3) << "every bottom point touches both boxes";
    EXPECT_EQ(CountRepeatedKeys(rows), 0) << "world indices " << near_index << ", " << far_index;
  }
  // An index beyond the object field's 22 bits is reported, not wrapped.
  far.setWorldArrayIndex(1 << 22);
  ExpectInputError([&] { CollectRows(source, {&body}); },
                   {"rigid contact", "object " + std::to_string(1 << 22), "22-bit"});
}

// Manifolds between objects whose broadphase ids differ by 2^20 (the old layout kept 20 bits).
TEST(RowKeyTest, ManifoldObjectsWhoseIdsDifferBy2To20GetDifferentKeys) {
  btSphereShape shape(0.1);
  btCollisionObject first, aliased, other;
  btBroadphaseProxy proxies[3];
  btCollisionObject* objects[3] = {&first, &aliased, &other};
  const int ids[3] = {5, 5 + (1 << 20), 6};
  for (int k = 0; k < 3; ++k) {
    objects[k]->setCollisionShape(&shape);
    proxies[k].m_uniqueId = ids[k];
    objects[k]->setBroadphaseHandle(&proxies[k]);
  }
  btContactSolverInfo info;
  RigidManifoldSource source(2);
  for (btCollisionObject* a : {&first, &aliased}) {
    btPersistentManifold manifold(a, &other, 0, 0.02, 0.02);
    btManifoldPoint point(btVector3(0, 0, 0), btVector3(0, 0, 0), btVector3(0, 0, 1), -0.001);
    point.m_combinedFriction = 0.5;  // a normal and two friction rows per point
    manifold.addManifoldPoint(point);
    source.AddManifold(manifold, nullptr, nullptr, info);
  }
  const std::vector<ConstraintRow> rows = CollectRows(source, {});
  ASSERT_EQ(rows.size(), 6u);
  EXPECT_EQ(CountRepeatedKeys(rows), 0);
  proxies[1].m_uniqueId = 1 << 22;
  btPersistentManifold manifold(&aliased, &other, 0, 0.02, 0.02);
  manifold.addManifoldPoint(
      btManifoldPoint(btVector3(0, 0, 0), btVector3(0, 0, 0), btVector3(0, 0, 1), -0.001));
  ExpectInputError([&] { source.AddManifold(manifold, nullptr, nullptr, info); },
                   {"rigid manifold", "object a " + std::to_string(1 << 22), "22-bit"});
}

// A joint with user id 1, then 86 unnamed joints (3 rows each): the old layout put the row count
// 256 and beyond onto the next joint id, so rows 256-258 aliased the first joint's rows.
TEST(RowKeyTest, JointRowsBeyond256DoNotAliasTheNextJointId) {
  btSphereShape shape(0.05);
  btRigidBody rigid(1.0, nullptr, &shape, btVector3(1, 1, 1));
  RigidIslandBody body(&rigid);
  body.BeginStep(kH);
  std::vector<std::unique_ptr<btPoint2PointConstraint>> joints;
  for (int j = 0; j < 87; ++j) {
    joints.push_back(std::make_unique<btPoint2PointConstraint>(rigid, btVector3(0.01 * j, 0, 0)));
    joints.back()->setUserConstraintId(j == 0 ? 1 : -1);
  }
  btContactSolverInfo info;
  JointSource source(4);
  for (auto& joint : joints) source.AddJoint(*joint, &body, nullptr, info);
  const std::vector<ConstraintRow> rows = CollectRows(source, {&body});
  ASSERT_EQ(rows.size(), 261u);
  EXPECT_EQ(CountRepeatedKeys(rows), 0);
}

}  // namespace
}  // namespace taut
