// "Leave out what a scene does not need", measured: each benchmark steps a scene and its
// baseline alternately in the same iterations and reports both times and their ratio (median of
// 5 repetitions). Ratios near 1 show a feature costs nothing when the scene does not use it.
#include <benchmark/benchmark.h>

#include <chrono>

#include "constraints/deformable_island_body.h"
#include "constraints/strain_limit_source.h"
#include "demos/scenes/bullet_world_holder.h"
#include "plugin/box_tet_mesher.h"

namespace taut {
namespace {

constexpr double kStep = 1.0 / 240.0;

// A 1 m beam of 20 x 4 x 4 cubes (1,920 tets), clamped at x = 0, in a world of its own.
struct BeamWorld {
  BulletWorldHolder holder;
  DeformableBody* beam;
  explicit BeamWorld(double ground_z = 0.0, bool ground = false) {
    if (ground) {
      holder.AddRigidBody(std::make_unique<btBoxShape>(btVector3(5, 5, 0.5)), 0.0,
                          btVector3(0, 0, ground_z - 0.5));
    }
    DeformableBodySettings settings;
    settings.name = "beam";
    settings.material = {1e6, 0.3, 1000.0};
    settings.mass_damping = 1.0;
    beam = holder.world.AddTetBody(
        MakeBoxTetMesh(Vec3(1.0, 0.2, 0.2), 20, 4, 4, Vec3(0, -0.1, 1.0)), settings);
    beam->FixNodesWhere([](const Vec3& X) { return X.x() < 1e-9; });
  }
  void Step() { holder.world.stepSimulation(kStep, 1, kStep); }
};

// Times one step of each world per iteration; counters ms_feature, ms_baseline, ratio.
template <typename A, typename B>
void RunPair(benchmark::State& state, A& feature, B& baseline) {
  for (int i = 0; i < 20; ++i) {
    feature.Step();
    baseline.Step();
  }
  double t_feature = 0.0, t_baseline = 0.0;
  int n = 0;
  for (auto _ : state) {
    auto t0 = std::chrono::steady_clock::now();
    feature.Step();
    auto t1 = std::chrono::steady_clock::now();
    baseline.Step();
    auto t2 = std::chrono::steady_clock::now();
    t_feature += std::chrono::duration<double, std::milli>(t1 - t0).count();
    t_baseline += std::chrono::duration<double, std::milli>(t2 - t1).count();
    ++n;
  }
  state.counters["ms_feature"] = t_feature / n;
  state.counters["ms_baseline"] = t_baseline / n;
  state.counters["ratio"] = t_feature / t_baseline;
}

// A static box far below the beam (bounds never overlap: no narrow phase, no contact rows) vs
// no rigid object at all.
void BM_LeaveOut_FarObjectSkipsTheNarrowPhase(benchmark::State& state) {
  BeamWorld with_far_ground(-50.0, true), alone;
  RunPair(state, with_far_ground, alone);
  state.counters["contact_rows"] = with_far_ground.holder.world.last_step_stats().rows_contact;
}

// Strain limits of +-50 % that the sagging beam never approaches (no rows: no LCP is built) vs
// no limits.
void BM_LeaveOut_InactiveLimitsBuildNoLcp(benchmark::State& state) {
  BeamWorld limited, unlimited;
  limited.holder.world.SetStrainLimits(limited.beam, StrainLimitSettings::Isotropic(0.5, 1.5));
  RunPair(state, limited, unlimited);
  state.counters["limit_rows"] = limited.holder.world.last_step_stats().rows_strain;
}

// Row evaluation alone on a stretched beam: isotropic hyperbolic limits (dV/dx drops out, not
// computed) vs per-axis limits (exact dV/dx through the SVD derivatives), every tet active.
void BM_LeaveOut_IsotropicVsPerAxisRows(benchmark::State& state) {
  BeamWorld world;
  DeformableBody& body = *world.beam;
  VecX x = body.x();
  for (int i = 0; i < body.num_nodes(); ++i) x[3 * i] *= 1.3;  // 30 % stretch along x
  StrainLimitSettings isotropic = StrainLimitSettings::Isotropic(0.9, 1.1);
  StrainLimitSettings per_axis =
      StrainLimitSettings::PerAxis(Vec3(0.9, 0.8, 0.7), Vec3(1.1, 1.2, 1.3));
  isotropic.activation_margin = per_axis.activation_margin = HUGE_VAL;
  StrainLimitSource iso(body, isotropic, 1), aniso(body, per_axis, 2);
  std::vector<ConstraintRow> rows;
  struct Eval {
    StrainLimitSource& source;
    const VecX& x;
    std::vector<ConstraintRow>& rows;
    void Step() {
      rows.clear();
      source.AppendRows(x, 0, rows);
    }
  } a{iso, x, rows}, b{aniso, x, rows};
  RunPair(state, a, b);
  state.counters["rows_isotropic"] = static_cast<double>(iso.AppendRows(x, 0, rows));
}

BENCHMARK(BM_LeaveOut_FarObjectSkipsTheNarrowPhase)
    ->Unit(benchmark::kMillisecond)
    ->Repetitions(5)
    ->ReportAggregatesOnly(true);
BENCHMARK(BM_LeaveOut_InactiveLimitsBuildNoLcp)
    ->Unit(benchmark::kMillisecond)
    ->Repetitions(5)
    ->ReportAggregatesOnly(true);
BENCHMARK(BM_LeaveOut_IsotropicVsPerAxisRows)
    ->Unit(benchmark::kMillisecond)
    ->Repetitions(5)
    ->ReportAggregatesOnly(true);

}  // namespace
}  // namespace taut
