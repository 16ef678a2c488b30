// taut's DeformableWorld next to Bullet 3.24's own implicit deformable world
// (btDeformableMultiBodyDynamicsWorld, co-rotated linear elasticity, implicit Newton-CG with
// setUseProjection(true)) on the same tet meshes, in one run:
//  - the tet beam cantilever of tet_beam_step_bench.cc (1 x 0.2 x 0.2 m, E = 200 kPa, nu = 0.3,
//    1000 kg/m^3, Rayleigh alpha = 1/s, x = 0 end fixed, gravity), 240 and 1,920 tets;
//  - a tet ball (R = 1 m, E = 150 kPa, nu = 0.3, 500 kg/m^3, as falling_sphere_scene.h but cut
//    into tets) dropped from 2 m onto a static box, 192 and 1,680 tets.
// Both engines get the same nodes, tets, lumped node masses, fixed nodes and h = 1/240 s. Each
// iteration restores both to the state saved after warm-up and times one batch of steps of each
// (thread CPU time); the counters hold per-step times, their ratio taut/Bullet and sanity figures
// (tip displacement, lowest node). Repetitions come from the command line (scripts/run_bench.sh).
#include <BulletSoftBody/btDeformableBodySolver.h>
#include <BulletSoftBody/btDeformableGravityForce.h>
#include <BulletSoftBody/btDeformableLinearElasticityForce.h>
#include <BulletSoftBody/btDeformableMultiBodyConstraintSolver.h>
#include <BulletSoftBody/btDeformableMultiBodyDynamicsWorld.h>
#include <BulletSoftBody/btSoftBody.h>
#include <BulletSoftBody/btSoftBodyHelpers.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <benchmark/benchmark.h>
#include <btBulletDynamicsCommon.h>
#include <time.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <set>
#include <utility>
#include <vector>

#include "demos/scenes/bullet_world_holder.h"
#include "demos/scenes/tet_beam_scene.h"
#include "plugin/box_tet_mesher.h"
#include "plugin/tet_element_model.h"

namespace taut {
namespace {

constexpr double kDt = 1.0 / 240.0;
constexpr double kGravity = -9.81;
constexpr double kBallRadius = 1.0;
constexpr double kDropHeight = 2.0;  // bottom of the ball above the ground at t = 0 [m]

// CPU seconds of this thread while running f (both engines are single-threaded; CPU time is
// immune to other processes sharing the machine).
template <typename F>
double TimeSeconds(F&& f) {
  auto now = [] {
    timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
  };
  const double start = now();
  f();
  return now() - start;
}

// The static ground both engines collide with: a 40 x 40 x 2 m box whose top face is z = 0.
btTransform GroundTransform() {
  return btTransform(btQuaternion::getIdentity(), btVector3(0, 0, -1));
}
btVector3 GroundHalfExtents() { return btVector3(20, 20, 1); }

// Bullet's deformable world with one tet body built by hand from a taut mesh (appendTetra, as
// btSoftBodyHelpers::CreateFromTetGenData does, without its text parsing), set up like Bullet's
// examples/DeformableDemo: linear elasticity + gravity forces, implicit solve with projection.
class BulletTetWorld {
 public:
  // mass: lumped node masses [kg] (0 = fixed node); E [Pa], nu, Rayleigh alpha [1/s], beta [s].
  BulletTetWorld(const TetMesh& mesh, const VecX& mass, double E, double nu, double alpha,
                 double beta, double friction, double margin)
      : world_(&dispatcher_, &broadphase_, &solver_, &configuration_, &body_solver_),
        gravity_(btVector3(0, 0, kGravity)),
        // Bullet takes Lamé parameters: mu = E / (2 (1 + nu)), lambda = E nu / ((1 + nu)(1 - 2
        // nu)).
        elasticity_(E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu)), alpha, beta) {
    solver_.setDeformableSolver(&body_solver_);
    world_.setGravity(btVector3(0, 0, kGravity));
    btSoftBodyWorldInfo& info = world_.getWorldInfo();
    info.m_gravity = btVector3(0, 0, kGravity);
    info.m_sparsesdf.setDefaultVoxelsz(0.25);
    info.m_sparsesdf.Reset();
    std::vector<btVector3> x;
    std::vector<btScalar> m;
    for (size_t i = 0; i < mesh.nodes.size(); ++i) {
      x.emplace_back(mesh.nodes[i].x(), mesh.nodes[i].y(), mesh.nodes[i].z());
      m.push_back(mass[static_cast<int>(i)]);
    }
    body_ = std::make_unique<btSoftBody>(&info, static_cast<int>(x.size()), x.data(), m.data());
    std::set<std::pair<int, int>> edges;
    for (const auto& t : mesh.tets) {
      // taut orders tets with det[X0-X3, X1-X3, X2-X3] > 0; Bullet's element volume is
      // det[X1-X0, X2-X0, X3-X0] / 6, of opposite sign for the same order: swap two nodes.
      body_->appendTetra(t[0], t[2], t[1], t[3]);
      for (int a = 0; a < 4; ++a)
        for (int b = a + 1; b < 4; ++b) edges.insert(std::minmax(t[a], t[b]));
    }
    for (const auto& [a, b] : edges) body_->appendLink(a, b);
    body_->initializeDmInverse();
    body_->m_tetraScratches.resize(body_->m_tetras.size());
    body_->m_tetraScratchesTn.resize(body_->m_tetras.size());
    body_->getCollisionShape()->setMargin(margin);
    body_->m_cfg.kKHR = 1;
    body_->m_cfg.kCHR = 1;
    body_->m_cfg.kDF = friction;
    // Node-vs-rigid contacts through the rigid shape's signed distance (SDF_RDN; without it the
    // nodes of a tet body pass through a box in 3.24).
    body_->m_cfg.collisions = btSoftBody::fCollision::SDF_RD | btSoftBody::fCollision::SDF_RDN;
    body_->m_sleepingThreshold = 0;
    body_->setActivationState(DISABLE_DEACTIVATION);
    btSoftBodyHelpers::generateBoundaryFaces(body_.get());
    world_.addSoftBody(body_.get());
    world_.addForce(body_.get(), &gravity_);
    world_.addForce(body_.get(), &elasticity_);
    world_.setImplicit(true);
    world_.setLineSearch(false);
    world_.setUseProjection(true);
    body_solver_.m_useProjection = true;
  }
  ~BulletTetWorld() {
    if (ground_) world_.removeRigidBody(ground_.get());
    world_.removeSoftBody(body_.get());
  }
  // Adds the static ground box with Coulomb friction 1.
  void AddGround() {
    ground_shape_ = std::make_unique<btBoxShape>(GroundHalfExtents());
    btRigidBody::btRigidBodyConstructionInfo info(0.0, nullptr, ground_shape_.get());
    info.m_startWorldTransform = GroundTransform();
    ground_ = std::make_unique<btRigidBody>(info);
    ground_->setFriction(1.0);
    world_.addRigidBody(ground_.get());
  }
  void Step() { world_.stepSimulation(kDt, 1, kDt); }
  // Saves / restores the node state (position, step-start position, velocity, last velocity).
  void Save() {
    saved_.clear();
    for (int i = 0; i < body_->m_nodes.size(); ++i) {
      const btSoftBody::Node& n = body_->m_nodes[i];
      saved_.push_back({n.m_x, n.m_q, n.m_v, n.m_vn});
    }
  }
  void Restore() {
    for (int i = 0; i < body_->m_nodes.size(); ++i) {
      btSoftBody::Node& n = body_->m_nodes[i];
      n.m_x = saved_[i][0];
      n.m_q = saved_[i][1];
      n.m_v = saved_[i][2];
      n.m_vn = saved_[i][3];
    }
  }
  Vec3 node_position(int i) const {
    const btVector3& x = body_->m_nodes[i].m_x;
    return Vec3(x.x(), x.y(), x.z());
  }
  int num_nodes() const { return body_->m_nodes.size(); }

 private:
  btSoftBodyRigidBodyCollisionConfiguration configuration_;
  btCollisionDispatcher dispatcher_{&configuration_};
  btDbvtBroadphase broadphase_;
  btDeformableBodySolver body_solver_;
  btDeformableMultiBodyConstraintSolver solver_;
  btDeformableMultiBodyDynamicsWorld world_;
  btDeformableGravityForce gravity_;
  btDeformableLinearElasticityForce elasticity_;
  std::unique_ptr<btSoftBody> body_;
  std::unique_ptr<btCollisionShape> ground_shape_;
  std::unique_ptr<btRigidBody> ground_;
  std::vector<std::array<btVector3, 4>> saved_;
};

// Lumped masses of a taut body with fixed nodes set to 0 (Bullet's marker for a fixed node).
VecX CalcBulletMasses(const DeformableBody& body) {
  VecX mass = body.mass();
  for (int i = 0; i < body.num_nodes(); ++i)
    if (body.node_kind(i) == NodeKind::kFixed) mass[i] = 0.0;
  return mass;
}

// The tet mesh of a taut tet body.
const TetMesh& MeshOf(const DeformableBody& body) {
  return dynamic_cast<const TetElementModel&>(body.model()).mesh();
}

// Saved x and v of a taut body.
struct TautState {
  VecX x, v;
  void Save(const DeformableBody& body) { x = body.x(), v = body.v(); }
  void Restore(DeformableBody& body) const { body.set_x(x), body.set_v(v); }
};

// Times `batch` steps of each engine per iteration from the restored state; sets the counters.
template <typename TautStep, typename BulletStep, typename Restore>
void TimeBatches(benchmark::State& state, int batch, TautStep taut_step, BulletStep bullet_step,
                 Restore restore) {
  double taut_s = 0.0, bullet_s = 0.0;
  int batches = 0;
  for (auto _ : state) {
    restore();
    const double t = TimeSeconds([&] {
      for (int k = 0; k < batch; ++k) taut_step();
    });
    const double b = TimeSeconds([&] {
      for (int k = 0; k < batch; ++k) bullet_step();
    });
    state.SetIterationTime(t + b);
    taut_s += t;
    bullet_s += b;
    ++batches;
  }
  const double steps = static_cast<double>(batches) * batch;
  state.counters["taut_ms_per_step"] = 1e3 * taut_s / steps;
  state.counters["bullet_ms_per_step"] = 1e3 * bullet_s / steps;
  state.counters["taut_over_bullet"] = taut_s / bullet_s;
}

// Beam of cells_x x (cells_x / 5)^2 cubes: 30 warm-up steps, then batches of 24 steps (0.1 s).
void BM_BeamTautVsBullet(benchmark::State& state) {
  const int cells_x = static_cast<int>(state.range(0));
  TetBeamScene scene({TetBeamScene::DefaultBeams()[0]}, cells_x, cells_x / 5);
  DeformableBody& body = scene.world().deformable_body(0);
  const DeformableBodySettings& s = body.settings();
  BulletTetWorld bullet(MeshOf(body), CalcBulletMasses(body), s.material.youngs_modulus,
                        s.material.poisson_ratio, s.mass_damping, s.stiffness_damping, s.friction,
                        s.contact_margin);
  std::vector<int> tip;
  for (int i = 0; i < body.num_nodes(); ++i)
    if (MeshOf(body).nodes[i].x() > 1.0 - 1e-9) tip.push_back(i);
  for (int i = 0; i < 30; ++i) scene.Step(kDt), bullet.Step();
  TautState saved;
  saved.Save(body);
  bullet.Save();
  TimeBatches(
      state, 24, [&] { scene.Step(kDt); }, [&] { bullet.Step(); },
      [&] { saved.Restore(body), bullet.Restore(); });
  // Sanity: tip-centre displacement after 30 + 24 steps (finite and non-zero if Bullet moves).
  Vec3 bullet_tip = Vec3::Zero();
  for (int i : tip) bullet_tip += bullet.node_position(i) - MeshOf(body).nodes[i];
  bullet_tip /= static_cast<double>(tip.size());
  const Vec3 taut_tip = scene.CalcTipDisplacement(0);
  state.counters["tets"] = static_cast<double>(MeshOf(body).tets.size());
  state.counters["taut_tip_z_m"] = taut_tip.z();
  state.counters["bullet_tip_z_m"] = bullet_tip.z();
  // Same co-rotated linear model and integrator order: the two tips should nearly coincide.
  state.counters["tip_difference_m"] = (taut_tip - bullet_tip).norm();
  state.counters["bullet_moves"] = std::isfinite(bullet_tip.norm()) && bullet_tip.norm() > 1e-4;
}

// Ball of radius R around centre cut from an n^3 box tet mesh: the 6 tets of every cube whose
// centre is inside the ball, nodes compacted.
TetMesh MakeTetBall(int n, const Vec3& centre) {
  const double cell = 2.0 * kBallRadius / n;
  const Vec3 corner = centre - Vec3::Constant(kBallRadius);
  const TetMesh box = MakeBoxTetMesh(Vec3::Constant(2.0 * kBallRadius), n, n, n, corner);
  TetMesh ball;
  ball.source = "tet ball";
  std::vector<int> new_index(box.nodes.size(), -1);
  for (const auto& t : box.tets) {
    const Vec3 mid = (box.nodes[t[0]] + box.nodes[t[1]] + box.nodes[t[2]] + box.nodes[t[3]]) / 4;
    const Vec3 cube = corner + cell * ((mid - corner) / cell).array().floor().matrix() +
                      Vec3::Constant(0.5 * cell);
    if ((cube - centre).norm() > kBallRadius) continue;
    std::array<int, 4> tet;
    for (int a = 0; a < 4; ++a) {
      if (new_index[t[a]] < 0) {
        new_index[t[a]] = static_cast<int>(ball.nodes.size());
        ball.nodes.push_back(box.nodes[t[a]]);
      }
      tet[a] = new_index[t[a]];
    }
    ball.tets.push_back(tet);
  }
  return ball;
}

// Lowest node z of n nodes given by position(i).
template <typename Position>
double CalcBottom(int n, Position position) {
  double z = HUGE_VAL;
  for (int i = 0; i < n; ++i) z = std::min(z, position(i).z());
  return z;
}

// Ball of n^3 grid cells: falls freely until its bottom is 0.1 m above the ground (untimed), then
// batches of 48 steps (0.2 s: impact and rebound) from that state.
void BM_BallDropTautVsBullet(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  BulletWorldHolder holder;
  holder.shapes.push_back(std::make_unique<btBoxShape>(GroundHalfExtents()));
  btRigidBody::btRigidBodyConstructionInfo info(0.0, nullptr, holder.shapes.back().get());
  info.m_startWorldTransform = GroundTransform();
  holder.rigid_bodies.push_back(std::make_unique<btRigidBody>(info));
  holder.rigid_bodies.back()->setFriction(1.0);
  holder.world.addRigidBody(holder.rigid_bodies.back().get());
  DeformableBodySettings settings = MakeSceneBodySettings("tet_ball", 150e3, 500.0);
  settings.contact_margin = 0.05;
  DeformableBody* body =
      holder.world.AddTetBody(MakeTetBall(n, Vec3(0, 0, kDropHeight + kBallRadius)), settings);
  BulletTetWorld bullet(MeshOf(*body), CalcBulletMasses(*body), 150e3, 0.3, 0.0, 0.0,
                        settings.friction, settings.contact_margin);
  bullet.AddGround();
  auto taut_position = [&](int i) { return body->node_position(i); };
  auto bullet_position = [&](int i) { return bullet.node_position(i); };
  while (CalcBottom(body->num_nodes(), taut_position) > 0.1) {
    holder.world.stepSimulation(kDt, 1, kDt);
    bullet.Step();
  }
  TautState saved;
  saved.Save(*body);
  bullet.Save();
  TimeBatches(
      state, 48, [&] { holder.world.stepSimulation(kDt, 1, kDt); }, [&] { bullet.Step(); },
      [&] { saved.Restore(*body), bullet.Restore(); });
  // Sanity, one more batch untimed: both balls stop at the ground (lowest node z over the batch).
  saved.Restore(*body), bullet.Restore();
  double taut_low = HUGE_VAL, bullet_low = HUGE_VAL;
  for (int k = 0; k < 48; ++k) {
    holder.world.stepSimulation(kDt, 1, kDt);
    bullet.Step();
    taut_low = std::min(taut_low, CalcBottom(body->num_nodes(), taut_position));
    bullet_low = std::min(bullet_low, CalcBottom(bullet.num_nodes(), bullet_position));
  }
  state.counters["taut_lowest_m"] = taut_low;
  state.counters["bullet_lowest_m"] = bullet_low;
  state.counters["tets"] = static_cast<double>(MeshOf(*body).tets.size());
  state.counters["taut_end_bottom_m"] = CalcBottom(body->num_nodes(), taut_position);
  state.counters["bullet_end_bottom_m"] = CalcBottom(bullet.num_nodes(), bullet_position);
}

BENCHMARK(BM_BeamTautVsBullet)->Arg(10)->Arg(20)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BallDropTautVsBullet)->Arg(4)->Arg(8)->UseManualTime()->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace taut
