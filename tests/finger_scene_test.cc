#include "demos/scenes/finger_scene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

namespace taut {
namespace {

// Runs every press of the scene to its end.
void RunPresses(FingerScene& scene, double dt) {
  for (int step = 0; step < 5000 && scene.current_press() < scene.num_presses(); ++step)
    scene.Step(dt);
  ASSERT_EQ(scene.current_press(), scene.num_presses()) << "presses did not finish";
}

// Paper A §5.2 / Fig. 3: at the same 40 N the anisotropic finger indents like the isotropic one
// when pressed flat (compliant nail normal, 0.75..1.25), but its tissue locks early on the side
// (0.98..1.02) and on the tip (0.95..1.05). Each press is compared with the isotropic press on the
// same side, so the contact geometry (a cylinder on its side, a cap on its tip) cancels.
TEST(FingerSceneTest, AnisotropicFingerIsCompliantOnlyAlongTheNailNormal) {
  FingerSceneSettings settings;
  settings.hold_time = 0.005;
  FingerScene scene(FingerScene::DefaultPresses(), settings);
  RunPresses(scene, 1e-3);
  // DefaultPresses order: flat, side, tip; anisotropic then isotropic.
  const FingerPressResult* r[3][2];
  for (int p = 0; p < 6; ++p) {
    r[p / 2][p % 2] = &scene.result(p);
    const FingerPressResult& result = scene.result(p);
    std::printf(
        "%-17s indentation %.4f mm, reaction %6.2f N (elastic %6.2f N), stop %-5s, "
        "violation %.1e, penetration %.1e m\n",
        result.name.c_str(), 1e3 * result.indentation, result.reaction, result.elastic_reaction,
        result.stop_reason.c_str(), result.max_violation, result.max_penetration);
    EXPECT_TRUE(result.touched) << result.name;
    // Accepted steps keep the limits within the solver's tolerance and nothing sinks in.
    EXPECT_LE(result.max_violation, 2.0 * settings.solver_tolerance) << result.name;
    EXPECT_LE(result.max_penetration, 1e-6) << result.name;
  }
  // Compliant along the nail normal: the full force, indentation within 15 % of isotropic.
  EXPECT_EQ(r[0][0]->stop_reason, "force");
  EXPECT_NEAR(r[0][0]->indentation / r[0][1]->indentation, 1.0, 0.15);
  // Stiff across and along the finger: the tissue locks below the force, at under half the
  // isotropic indentation.
  for (int axis : {1, 2}) {
    EXPECT_EQ(r[axis][0]->stop_reason, "lock") << r[axis][0]->name;
    EXPECT_LT(r[axis][0]->reaction, settings.target_force) << r[axis][0]->name;
    EXPECT_LT(r[axis][0]->indentation, 0.5 * r[axis][1]->indentation) << r[axis][0]->name;
  }
  // Flat and side share the round cross-section: the anisotropic finger indents at least twice
  // as deep flat, the isotropic one equally (within 5 %).
  EXPECT_GT(r[0][0]->indentation, 2.0 * r[1][0]->indentation);
  EXPECT_NEAR(r[0][1]->indentation / r[1][1]->indentation, 1.0, 0.05);
  // Isotropic presses reach the target force and no limit row is active, so the table's contact
  // forces must equal the elastic force on the bone nodes (the force measure is right).
  for (int axis = 0; axis < 3; ++axis) {
    const FingerPressResult& iso = *r[axis][1];
    EXPECT_EQ(iso.stop_reason, "force") << iso.name;
    EXPECT_NEAR(iso.reaction, settings.target_force, 0.05 * settings.target_force) << iso.name;
    EXPECT_NEAR(iso.reaction, iso.elastic_reaction, 0.01 * iso.elastic_reaction) << iso.name;
  }
}

TEST(FingerSceneTest, BoneIsInsideTheFleshAndBadSettingsThrow) {
  FingerScene scene({{FingerPressAxis::kFlat, FingerScene::Isotropic()}});
  EXPECT_GT(scene.body_mesh().tets.size(), 300u);
  EXPECT_LT(scene.body_mesh().tets.size(), 450u);
  const std::vector<int> boundary = CalcBoundaryNodes(scene.body_mesh());
  ASSERT_FALSE(scene.bone_nodes().empty());
  for (int node : scene.bone_nodes())
    EXPECT_FALSE(std::binary_search(boundary.begin(), boundary.end(), node)) << node;
  FingerSceneSettings bad;
  bad.target_force = 0.0;
  EXPECT_THROW(FingerScene({{FingerPressAxis::kTip, FingerScene::Isotropic()}}, bad), InputError);
  EXPECT_THROW(FingerScene({}), InputError);
}

// A locked advance (the bone pushes tissue whose limits already hold it against the table: no
// velocity satisfies every row) cannot be certified; the scene takes it back from a snapshot and
// steps again at the last travel, so every step it keeps is certified. The taken-back advances
// did break the limits, so taking them back was needed.
TEST(FingerSceneTest, LockedAdvancesAreTakenBackSoEveryKeptStepIsCertified) {
  const FingerSceneSettings settings;
  FingerScene scene(FingerScene::DefaultPresses(), settings);
  int steps = 0, unconverged = 0, locks = 0;
  for (; steps < 5000 && scene.current_press() < scene.num_presses(); ++steps) {
    scene.Step(1e-3);
    unconverged += scene.world().last_step_stats().converged ? 0 : 1;
  }
  ASSERT_EQ(scene.current_press(), scene.num_presses());
  for (int p = 0; p < scene.num_presses(); ++p) {
    const FingerPressResult& result = scene.result(p);
    EXPECT_LE(result.max_violation, 2.0 * settings.solver_tolerance) << result.name;
    if (result.stop_reason != "lock") continue;
    ++locks;
    std::printf("%s: the advance taken back reached violation %.2e, penetration %.2e m\n",
                result.name.c_str(), result.lock_violation, result.lock_penetration);
    EXPECT_GT(std::max(result.lock_violation / settings.solver_tolerance,
                       result.lock_penetration / settings.lock_penetration),
              1.0)
        << result.name;
  }
  std::printf("%d steps, %d unconverged, %d presses locked\n", steps, unconverged, locks);
  EXPECT_EQ(locks, 2);  // side and tip, anisotropic
  EXPECT_EQ(unconverged, 0);
}

// Both paths must tell a locked advance from a feasible one the same way. The primal path's
// Newton loop used to stop on its relative decrement (1e-9 of ||v - v*||_A^2, a scale the contact
// forces set) with a limit row still 2e-5 past the finger's 1e-5 tolerance; its multiplier
// iterations then cycled to the cap, and the scene took the flat anisotropic press's advance back
// as "locked" at 27 N instead of pressing on to 40 N (docs/math.md §5.8, rows still moving).
TEST(FingerSceneTest, ThePrimalPathLocksTheAnisotropicFingerWhereTheDualPathDoes) {
  const FingerSceneSettings settings;
  const std::vector<FingerPress> presses = {{FingerPressAxis::kFlat, FingerScene::Anisotropic()},
                                            {FingerPressAxis::kTip, FingerScene::Anisotropic()}};
  std::vector<FingerPressResult> results[2];
  for (IslandSolverKind solver : {IslandSolverKind::kDual, IslandSolverKind::kPrimal}) {
    FingerScene scene(presses, settings);
    scene.world().mutable_solver_settings().solver = solver;
    RunPresses(scene, 1e-3);
    for (int p = 0; p < scene.num_presses(); ++p) {
      const FingerPressResult& result = scene.result(p);
      std::printf("%-6s %-17s indentation %.4f mm, reaction %6.2f N, stop %s\n",
                  GetIslandSolverName(solver), result.name.c_str(), 1e3 * result.indentation,
                  result.reaction, result.stop_reason.c_str());
      EXPECT_LE(result.max_violation, 2.0 * settings.solver_tolerance) << result.name;
      results[solver == IslandSolverKind::kPrimal].push_back(result);
    }
  }
  const std::vector<FingerPressResult>& dual = results[0];
  const std::vector<FingerPressResult>& primal = results[1];
  // Flat: compliant along the nail normal, the full force on either path; tip: locked on both.
  EXPECT_EQ(dual[0].stop_reason, "force");
  EXPECT_EQ(dual[1].stop_reason, "lock");
  for (int p = 0; p < 2; ++p) {
    EXPECT_EQ(primal[p].stop_reason, dual[p].stop_reason) << primal[p].name;
    EXPECT_NEAR(primal[p].indentation, dual[p].indentation, 0.02 * dual[p].indentation)
        << primal[p].name;
    EXPECT_NEAR(primal[p].reaction, dual[p].reaction, 0.05 * dual[p].reaction) << primal[p].name;
  }
}

// The dual path's look-ahead rows (docs/math.md §5.7, "Rows found at the QP step"): in the
// flat anisotropic press the QP's push moves elements outside the activation margin past their
// limits; without those rows the merit halves every full step. Same press, same answer, fewer
// SQP iterations.
TEST(FingerSceneTest, RowsFoundAtTheQpStepCutTheFlatPressSqpIterations) {
  FingerPressResult result[2];
  for (int passes : {0, 3}) {
    FingerScene scene({FingerScene::DefaultPresses()[0]}, FingerSceneSettings());
    scene.world().mutable_solver_settings().max_row_discovery_passes = passes;
    // From the papers' start v*, where the QP's push crosses the margins (the warm-start
    // velocity starts near the answer and needs few rows found).
    scene.world().mutable_solver_settings().warm_start_velocity = false;
    RunPresses(scene, 1e-3);
    result[passes > 0] = scene.result(0);
  }
  std::printf(
      "flat anisotropic press: SQP iterations per step %.2f without look-ahead rows, "
      "%.2f with; indentation %.4f / %.4f mm, reaction %.3f / %.3f N\n",
      result[0].mean_sqp_iterations, result[1].mean_sqp_iterations, 1e3 * result[0].indentation,
      1e3 * result[1].indentation, result[0].reaction, result[1].reaction);
  EXPECT_LT(result[1].mean_sqp_iterations, 0.6 * result[0].mean_sqp_iterations);
  EXPECT_EQ(result[1].stop_reason, result[0].stop_reason);
  EXPECT_NEAR(result[1].indentation, result[0].indentation, 0.01 * result[0].indentation);
  EXPECT_NEAR(result[1].reaction, result[0].reaction, 0.01 * result[0].reaction);
  EXPECT_LE(result[1].max_violation, 2.0 * FingerSceneSettings().solver_tolerance);
}

// The dual path's certificate steps (SqpSettings::certificate_steps, docs/math.md §5.7): in the
// holds between presses the merit halves full SQP steps, so the SQP converges linearly at rate
// 1/2 and can end its 10 iterations uncertified; taking the full steps that lower the
// certificate's residual certifies those steps. Counted over the demo's run (520 steps of 1 ms).
// Since the QPs are solved exactly (the active-set polish with row-relative regularization) the
// steps left uncertified without them fell from 15 or more to 5 (with them: 2).
TEST(FingerSceneTest, CertificateStepsCertifyTheHoldsBetweenPresses) {
  int unconverged[2] = {0, 0};
  long sqp[2] = {0, 0};
  double max_violation[2] = {0.0, 0.0};
  for (int on = 0; on < 2; ++on) {
    // Every step counted as stepped: locked advances kept, not taken back.
    FingerSceneSettings settings;
    settings.take_back_locked_advances = false;
    FingerScene scene(FingerScene::DefaultPresses(), settings);
    scene.world().mutable_solver_settings().certificate_steps = on != 0;
    // From the papers' start v* (the warm-start velocity starts the holds at their answer).
    scene.world().mutable_solver_settings().warm_start_velocity = false;
    // The dual path's own figures: no second solve on the primal path for its failed steps, and
    // no primal steps after a locked advance stalled (kept here, not taken back).
    scene.world().mutable_solver_settings().retry_failed_step_on_other_path = false;
    scene.world().mutable_solver_settings().solver = IslandSolverKind::kDual;
    for (int step = 0; step < 5000 && scene.current_press() < scene.num_presses(); ++step) {
      scene.Step(1e-3);
      const StepStats& stats = scene.world().last_step_stats();
      unconverged[on] += stats.converged ? 0 : 1;
      sqp[on] += stats.sqp_iterations;
      max_violation[on] = std::max(max_violation[on], stats.violation_after);
    }
    ASSERT_EQ(scene.current_press(), scene.num_presses());
  }
  std::printf(
      "unconverged steps: %d with certificate steps (max violation %.2e, %ld SQP iterations), "
      "%d without (%.2e, %ld)\n",
      unconverged[1], max_violation[1], sqp[1], unconverged[0], max_violation[0], sqp[0]);
  EXPECT_LE(unconverged[1], 2);
  EXPECT_GT(unconverged[0], unconverged[1]);
  EXPECT_LT(sqp[1], sqp[0]);
  EXPECT_LE(max_violation[1], max_violation[0] * 1.01);
}

// The dual path's warm-start velocity (SqpSettings::warm_start_velocity, docs/math.md §5.7): the
// SQP starts from v* + A^-1 J_0^T lambda_0, the last step's impulses on the rows at the step's
// start, instead of v*. Over the demo's six presses: the same presses (stop reasons, reactions
// and indentations within 1 %), every step certified, and fewer SQP iterations and PGS sweeps.
TEST(FingerSceneTest, WarmStartVelocityKeepsThePressesWithFewerIterations) {
  FingerPressResult result[2][6];
  long sqp[2] = {0, 0}, sweeps[2] = {0, 0}, unconverged[2] = {0, 0};
  for (int on = 0; on < 2; ++on) {
    FingerScene scene(FingerScene::DefaultPresses(), FingerSceneSettings());
    scene.world().mutable_solver_settings().warm_start_velocity = on != 0;
    for (int step = 0; step < 5000 && scene.current_press() < scene.num_presses(); ++step) {
      scene.Step(1e-3);
      const StepStats& stats = scene.world().last_step_stats();
      sqp[on] += stats.sqp_iterations;
      sweeps[on] += stats.pgs_sweeps;
      unconverged[on] += stats.converged ? 0 : 1;
    }
    ASSERT_EQ(scene.current_press(), scene.num_presses());
    for (int p = 0; p < scene.num_presses(); ++p) result[on][p] = scene.result(p);
  }
  std::printf("SQP iterations %ld -> %ld, PGS sweeps %ld -> %ld, unconverged %ld -> %ld\n", sqp[0],
              sqp[1], sweeps[0], sweeps[1], unconverged[0], unconverged[1]);
  for (int p = 0; p < 6; ++p) {
    const FingerPressResult& off = result[0][p];
    const FingerPressResult& on = result[1][p];
    EXPECT_EQ(on.stop_reason, off.stop_reason) << off.name;
    EXPECT_NEAR(on.reaction, off.reaction, 0.01 * off.reaction) << off.name;
    EXPECT_NEAR(on.indentation, off.indentation, 0.01 * off.indentation) << off.name;
  }
  EXPECT_EQ(unconverged[1], 0);
  EXPECT_LT(sqp[1], 0.85 * sqp[0]);
  EXPECT_LT(sweeps[1], 0.5 * sweeps[0]);
}

}  // namespace
}  // namespace taut
