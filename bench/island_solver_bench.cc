// Constrained step vs the unconstrained step of the same body, for the dual (PGS per QP inside
// the SQP), primal (augmented-Lagrangian Newton) and auto island solvers (issue 11, "Targets"):
//   tet_iso, tet_aniso  the soft 5 kPa isotropic / anisotropic beams of the tet_beam scene (240
//                       tets, limits 0.96..1.04), warmed up until they swing in their limits
//   tet_aniso_no_frame  tet_aniso without the frame factor's curvature (full_frame_curvature off)
//   hex_0.1J            the hex_beam scene's beam with U_max = 0.1 J (56 hexes)
//   slab_rest/N         a soft limited slab of N cells along x resting on the ground (contact)
//   slab_roll/N         a soft limited slab (bottom fixed) under a rolling rigid sphere
//   rest_box            a rigid box on a limited soft block on the ground: the box height change
//                       over the last second of a 2 s rest (warm-up: the first second)
// Every case also runs as "none": the same body without limits, ground or rigid body, so it has no
// rows and its step is the unconstrained step alone; scripts/run_bench.sh divides by it.
// Only stepSimulation is inside the timed loop (warm-up and scene setup are outside). Counters,
// per repetition (Google Benchmark reports their medians over the repetitions):
//   ms_step        median thread CPU time per step [ms]
//   ms_step_wall   median StepStats::ms_total [ms] (steady clock)
//   ms_unc         median StepStats::ms_unconstrained [ms] (the same steps' stage 2)
//   in_step_ratio  sum ms_total / sum ms_unconstrained over the timed steps (the steps.csv ratio)
//   sqp_mean, newton_mean, pcg_mean (PCG iterations on kept factors and model steps),
//   factorizations_mean (Newton matrices factored), pgs_sweeps_mean, rows_mean  per step
//   unconverged    steps with StepStats::converged false; max_violation  max violation_after
//   primal_share   islands solved by the primal path / islands solved
//   height_change_mm (rest_box) |box z(2 s) - box z(1 s)|; max_drift_mm the largest |z - z(1 s)|.
#include <benchmark/benchmark.h>
#include <time.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "demos/scenes/bullet_world_holder.h"
#include "demos/scenes/hex_beam_scene.h"
#include "demos/scenes/scene.h"
#include "demos/scenes/tet_beam_scene.h"
#include "plugin/box_tet_mesher.h"

namespace taut {
namespace {

constexpr double kDt = 1.0 / 240.0;

double ThreadCpuMs() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
}

double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// A world ready to step: either a scene or a bare holder, and the rigid body to follow (or null).
struct Setup {
  std::unique_ptr<Scene> scene;
  std::unique_ptr<BulletWorldHolder> holder;
  btRigidBody* rigid = nullptr;
  DeformableWorld& world() { return scene ? scene->world() : holder->world; }
};

// What a case is and how long it runs: warm-up and timed steps per repetition.
struct Case {
  std::string name;
  std::function<Setup(bool constrained)> make;
  int warmup_steps;
  int timed_steps;
  int repetitions;
  // true: repetitions continue the warmed-up world of the first one (long warm-ups); false:
  // every repetition builds and warms up its own (rest_box: each measures t = 1..2 s).
  bool continue_repetitions = true;
  bool rest_height = false;  // report height_change_mm / max_drift_mm of the rigid body
};

// The tet_beam scene's beam `index` (DefaultBeams: 1 unlimited soft, 2 anisotropic, 3
// isotropic) alone, 10 x 2 x 2 cells (240 tets); unconstrained: the unlimited soft beam.
Setup MakeTetBeam(int index, bool constrained) {
  const auto beams = TetBeamScene::DefaultBeams();
  Setup s;
  s.scene = std::make_unique<TetBeamScene>(
      std::vector<TetBeamScene::Beam>{constrained ? beams[index] : beams[1]}, 10, 2);
  return s;
}

// The anisotropic beam with the stretch term alone in the Newton matrix (the frame factor's
// curvature off, docs/math.md §5.9); unconstrained: the same unlimited beam as the others.
Setup MakeTetBeamWithoutFrameCurvature(bool constrained) {
  auto beams = TetBeamScene::DefaultBeams();
  beams[2].limits->full_frame_curvature = false;
  Setup s;
  s.scene = std::make_unique<TetBeamScene>(
      std::vector<TetBeamScene::Beam>{constrained ? beams[2] : beams[1]}, 10, 2);
  return s;
}

// The hex_beam scene's beam limited to 0.1 J per element; unconstrained: the linear beam.
Setup MakeHexBeam(bool constrained) {
  const auto beams = HexBeamScene::DefaultBeams();
  Setup s;
  s.scene = std::make_unique<HexBeamScene>(
      std::vector<HexBeamScene::Beam>{constrained ? beams[3] : beams[0]});
  return s;
}

// A soft (E = 5 kPa, 1000 kg/m^3) 0.8 x 0.8 x 0.12 m slab of n x n x max(2, n / 4) cells,
// limits 0.96..1.04, dropped 0.5 mm onto the ground (its own weight alone would compress the
// bottom by ~20 %). Unconstrained: no ground, no limits (free fall, no rows).
Setup MakeRestingSlab(int n, bool constrained) {
  Setup s;
  s.holder = std::make_unique<BulletWorldHolder>();
  if (constrained) s.holder->AddStaticGround();
  auto mesh = std::make_shared<TetMesh>(
      MakeBoxTetMesh(Vec3(0.8, 0.8, 0.12), n, n, std::max(2, n / 4), Vec3(-0.4, -0.4, 0.0005)));
  mesh->source = "resting slab";
  DeformableBody* body =
      s.holder->world.AddTetBody(mesh, MakeSceneBodySettings("slab", 5e3, 1000.0, 1.0));
  if (constrained)
    s.holder->world.SetStrainLimits(body, StrainLimitSettings::Isotropic(0.96, 1.04));
  return s;
}

// A soft (E = 20 kPa) 1.2 x 0.4 x 0.1 m slab of 3n x n x max(2, n / 3) cells, bottom fixed,
// limits 0.96..1.04, and a 2 kg rigid sphere (r = 8 cm) rolling along x at 1 m/s across it.
// Unconstrained: the slab alone, no limits.
Setup MakeRollingSlab(int n, bool constrained) {
  Setup s;
  s.holder = std::make_unique<BulletWorldHolder>();
  const double top = 0.1;
  auto mesh = std::make_shared<TetMesh>(
      MakeBoxTetMesh(Vec3(1.2, 0.4, top), 3 * n, n, std::max(2, n / 3), Vec3(-0.6, -0.2, 0.0)));
  mesh->source = "rolling slab";
  DeformableBody* body =
      s.holder->world.AddTetBody(mesh, MakeSceneBodySettings("slab", 20e3, 1000.0, 1.0));
  body->FixNodesWhere([](const Vec3& X) { return X.z() < 1e-9; });
  if (!constrained) return s;
  s.holder->world.SetStrainLimits(body, StrainLimitSettings::Isotropic(0.96, 1.04));
  const double r = 0.08, v = 1.0;
  s.rigid = s.holder->AddRigidBody(std::make_unique<btSphereShape>(r), 2.0,
                                   btVector3(-0.4, 0.0, top + r + 0.001), 0.8);
  s.rigid->setActivationState(DISABLE_DEACTIVATION);
  s.rigid->setLinearVelocity(btVector3(v, 0, 0));
  s.rigid->setAngularVelocity(btVector3(0, v / r, 0));
  return s;
}

// A soft (E = 20 kPa) 0.2 m cube of 5 x 5 x 5 cells (750 tets), limits 0.96..1.04, on the
// ground, with a 1 kg rigid 0.1 m box on top. Unconstrained: the block alone, no ground/limits.
Setup MakeRestBox(bool constrained) {
  Setup s;
  s.holder = std::make_unique<BulletWorldHolder>();
  const double size = 0.2, lift = 0.0005;
  auto mesh = std::make_shared<TetMesh>(
      MakeBoxTetMesh(Vec3(size, size, size), 5, 5, 5, Vec3(-0.1, -0.1, lift)));
  mesh->source = "rest block";
  DeformableBody* body =
      s.holder->world.AddTetBody(mesh, MakeSceneBodySettings("block", 20e3, 1000.0, 1.0));
  if (!constrained) return s;
  s.holder->AddStaticGround();
  s.holder->world.SetStrainLimits(body, StrainLimitSettings::Isotropic(0.96, 1.04));
  const double half = 0.05;
  s.rigid = s.holder->AddRigidBody(std::make_unique<btBoxShape>(btVector3(half, half, half)), 1.0,
                                   btVector3(0, 0, lift + size + 0.001 + half), 0.8);
  s.rigid->setActivationState(DISABLE_DEACTIVATION);
  return s;
}

double RigidZ(const Setup& s) {
  return static_cast<double>(s.rigid->getWorldTransform().getOrigin().z());
}

// Warm-up outside the timed loop, then one stepSimulation per iteration; counters as above.
void RunCase(benchmark::State& state, const Case& c, bool constrained, IslandSolverKind kind,
             bool dual_curvature) {
  // The warmed-up world of the last (case, path), kept for its next repetition.
  static std::string cached_key;
  static std::unique_ptr<Setup> cached;
  const std::string key = c.name + (constrained ? "/" : "/none/") + GetIslandSolverName(kind) +
                          (dual_curvature ? "_curved" : "");
  if (!c.continue_repetitions || key != cached_key || !cached) {
    cached.reset();
    cached = std::make_unique<Setup>(c.make(constrained));
    cached_key = key;
    cached->world().mutable_solver_settings().solver = kind;
    cached->world().mutable_solver_settings().dual_curvature = dual_curvature;
    for (int i = 0; i < c.warmup_steps; ++i) cached->world().stepSimulation(kDt, 1, kDt);
  }
  Setup& s = *cached;
  DeformableWorld& world = s.world();
  const double x0 = s.rigid ? static_cast<double>(s.rigid->getWorldTransform().getOrigin().x()) : 0;
  const double z0 = s.rigid ? RigidZ(s) : 0.0;
  double max_drift = 0.0;
  std::vector<double> cpu_ms, wall_ms, unc_ms;
  double sum_total = 0.0, sum_unc = 0.0, max_violation = 0.0;
  long sqp = 0, newton = 0, pcg = 0, factorizations = 0, sweeps = 0, rows = 0, unconverged = 0,
       dual = 0, primal = 0;
  for (auto _ : state) {
    const double t0 = ThreadCpuMs();
    world.stepSimulation(kDt, 1, kDt);
    cpu_ms.push_back(ThreadCpuMs() - t0);
    const StepStats& st = world.last_step_stats();
    wall_ms.push_back(st.ms_total);
    unc_ms.push_back(st.ms_unconstrained);
    sum_total += st.ms_total;
    sum_unc += st.ms_unconstrained;
    sqp += st.sqp_iterations;
    newton += st.newton_iterations;
    pcg += st.pcg_iterations;
    factorizations += st.newton_factorizations;
    sweeps += st.pgs_sweeps;
    rows += st.rows_total();
    unconverged += st.converged ? 0 : 1;
    dual += st.islands_dual;
    primal += st.islands_primal;
    max_violation = std::max(max_violation, st.violation_after);
    if (s.rigid && c.rest_height) max_drift = std::max(max_drift, std::abs(RigidZ(s) - z0));
  }
  const double steps = static_cast<double>(cpu_ms.size());
  const DeformableBody& body = world.deformable_body(0);
  state.counters["elements"] = body.model().num_elements();
  state.counters["dofs"] = 3.0 * body.num_nodes();
  state.counters["ms_step"] = Median(cpu_ms);
  state.counters["ms_step_wall"] = Median(wall_ms);
  state.counters["ms_unc"] = Median(unc_ms);
  state.counters["in_step_ratio"] = sum_unc > 0.0 ? sum_total / sum_unc : 0.0;
  state.counters["sqp_mean"] = sqp / steps;
  state.counters["newton_mean"] = newton / steps;
  state.counters["pcg_mean"] = pcg / steps;
  state.counters["factorizations_mean"] = factorizations / steps;
  state.counters["pgs_sweeps_mean"] = sweeps / steps;
  state.counters["rows_mean"] = rows / steps;
  state.counters["unconverged"] = static_cast<double>(unconverged);
  state.counters["steps"] = steps;
  state.counters["max_violation"] = max_violation;
  state.counters["primal_share"] =
      dual + primal > 0 ? static_cast<double>(primal) / (dual + primal) : 0.0;
  if (s.rigid && !c.rest_height) {
    // Sanity of the rolling body: distance travelled along x and its centre height [m].
    state.counters["rigid_dx_m"] = s.rigid->getWorldTransform().getOrigin().x() - x0;
    state.counters["rigid_z_m"] = RigidZ(s);
  }
  if (s.rigid && c.rest_height) {
    state.counters["height_change_mm"] = 1e3 * std::abs(RigidZ(s) - z0);
    state.counters["max_drift_mm"] = 1e3 * max_drift;
  }
}

std::vector<Case> MakeCases() {
  std::vector<Case> cases = {
      {"tet_iso", [](bool c) { return MakeTetBeam(3, c); }, 60, 60, 3},
      {"tet_aniso", [](bool c) { return MakeTetBeam(2, c); }, 60, 60, 3},
      {"tet_aniso_no_frame", [](bool c) { return MakeTetBeamWithoutFrameCurvature(c); }, 60, 60, 3},
      {"hex_0.1J", [](bool c) { return MakeHexBeam(c); }, 60, 120, 3},
  };
  // 768 and 2,592 tets (n = 16, 6,144 tets, is not registered: the dual path takes 1.6 s per
  // step at 2,592 tets, growing with exponent ~2.7).
  for (int n : {8, 12})
    cases.push_back({"slab_rest/" + std::to_string(n),
                     [n](bool c) { return MakeRestingSlab(n, c); }, 40, n <= 8 ? 20 : 8, 3});
  for (int n : {4, 6, 8})
    cases.push_back({"slab_roll/" + std::to_string(n),
                     [n](bool c) { return MakeRollingSlab(n, c); }, 30, 20, 3});
  cases.push_back({"rest_box", [](bool c) { return MakeRestBox(c); }, 240, 240, 1, false, true});
  return cases;
}

// BM_IslandSolver/<case>/<solver>, solver in none (the unconstrained twin), dual, dual_curved
// (the dual path with SqpSettings::dual_curvature), primal, auto.
const bool kRegistered = [] {
  static const std::vector<Case> cases = MakeCases();
  struct Path {
    const char* name;
    bool constrained;
    IslandSolverKind kind;
    bool dual_curvature;
  };
  const Path paths[] = {{"none", false, IslandSolverKind::kAuto, false},
                        {"dual", true, IslandSolverKind::kDual, false},
                        {"dual_curved", true, IslandSolverKind::kDual, true},
                        {"primal", true, IslandSolverKind::kPrimal, false},
                        {"auto", true, IslandSolverKind::kAuto, false}};
  for (const Case& c : cases)
    for (const Path& p : paths)
      benchmark::RegisterBenchmark(("BM_IslandSolver/" + c.name + "/" + p.name).c_str(),
                                   [&c, p](benchmark::State& state) {
                                     RunCase(state, c, p.constrained, p.kind, p.dual_curvature);
                                   })
          ->Iterations(c.timed_steps)
          ->Repetitions(c.repetitions)
          ->ReportAggregatesOnly(true)
          ->Unit(benchmark::kMillisecond);
  return true;
}();

}  // namespace
}  // namespace taut
