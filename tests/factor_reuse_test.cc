// Factor reuse in the unconstrained solve (ImplicitSystem::SolveStep): a body large enough to
// reuse its factor solves by CG on the kept factor, follows the trajectory of the body that
// factors every step to the CG tolerance, and still applies this step's exact A^-1 to the
// constraint solve's right-hand sides.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>

#include "plugin/box_tet_mesher.h"
#include "plugin/deformable_body.h"
#include "plugin/tet_element_model.h"

namespace taut {
namespace {

// A soft 1 x 0.2 x 0.2 m cantilever of 20 x 4 x 4 cubes (1,920 tets), clamped at x = 0: its
// factorization costs ~11 PCG iterations, above the default min_refactor_cost.
std::unique_ptr<DeformableBody> MakeReuseCantilever(bool reuse) {
  DeformableBodySettings settings;
  settings.name = reuse ? "reusing" : "factoring";
  settings.material = {1e5, 0.3, 1000.0};
  settings.factor_reuse.enabled = reuse;
  auto body = std::make_unique<DeformableBody>(
      std::make_unique<TetElementModel>(std::make_shared<const TetMesh>(MakeBoxTetMesh(
                                            Vec3(1.0, 0.2, 0.2), 20, 4, 4, Vec3::Zero())),
                                        settings.material),
      settings);
  body->FixNodesWhere([](const Vec3& x) { return x.x() < 1e-9; });
  return body;
}

constexpr double kReuseStep = 1.0 / 240.0;
const Vec3 kReuseGravity(0.0, 0.0, -9.81);

// Steps the body three times and begins a fourth step, whose unconstrained solve reuses the kept
// factor; false when the body factors with CHOLMOD (whose factors are never kept).
bool BeginAStepOnTheKeptFactor(DeformableBody& body) {
  for (int step = 0; step < 3; ++step) {
    if (step == 1 && body.system().uses_cholmod()) return false;
    body.BeginStep(kReuseStep, kReuseGravity);
    body.EndStep(kReuseStep);
  }
  body.BeginStep(kReuseStep, kReuseGravity);
  return true;
}

// A smooth right-hand side on the body's free DOFs, zero on the fixed ones.
VecX MakeFreeDofRhs(const DeformableBody& body) {
  VecX b = VecX::Zero(3 * body.num_nodes());
  for (int i = 0; i < b.size(); ++i)
    if (body.system().free_index(i) >= 0) b[i] = std::sin(0.37 * i);
  return b;
}

TEST(FactorReuseTest, ReusingBodyFollowsTheFactoringBodyToTheCgTolerance) {
  auto reusing = MakeReuseCantilever(true);
  auto factoring = MakeReuseCantilever(false);
  reusing->BeginStep(kReuseStep, kReuseGravity);  // builds the system, choosing its backend
  if (reusing->system().uses_cholmod()) GTEST_SKIP() << "CHOLMOD factors are not reused";
  reusing = MakeReuseCantilever(true);
  int reused_steps = 0;
  for (int step = 0; step < 40; ++step) {
    reusing->BeginStep(kReuseStep, kReuseGravity);
    factoring->BeginStep(kReuseStep, kReuseGravity);
    EXPECT_EQ(factoring->last_pcg_iterations(), 0);
    if (reusing->last_pcg_iterations() > 0) ++reused_steps;
    reusing->EndStep(kReuseStep);
    factoring->EndStep(kReuseStep);
  }
  EXPECT_GE(reused_steps, 30) << "the kept factor was hardly used";
  // The tip has sagged (the comparison is not of two bodies at rest).
  const double sag = (factoring->x() - MakeReuseCantilever(false)->x()).cwiseAbs().maxCoeff();
  ASSERT_GT(sag, 1e-3);
  const double gap = (reusing->x() - factoring->x()).cwiseAbs().maxCoeff();
  // Each step's CG error is below the tolerance relative to the step: the gap stays below it
  // relative to the sag (measured 0.2 of it at 1e-6, 0.1 at 1e-10).
  EXPECT_LT(gap, FactorReuseSettings().pcg_tolerance * sag) << "sag " << sag << " m";
}

// Where A has not changed since the kept factor was made (a body at rest), CG's first
// application of the factor is already exact: the reused step stops there, and gives the
// factored step's answer to rounding. (The later applications read the single-precision copy of
// L; this first one is in double, so resting bodies keep their exact answer.)
TEST(FactorReuseTest, UnchangedMatrixIsSolvedExactlyByTheKeptFactor) {
  auto body = MakeReuseCantilever(true);
  auto factoring = MakeReuseCantilever(false);
  body->BeginStep(kReuseStep, kReuseGravity);  // factors A
  if (body->system().uses_cholmod()) GTEST_SKIP() << "CHOLMOD factors are not reused";
  ASSERT_EQ(body->last_pcg_iterations(), 0);
  factoring->BeginStep(kReuseStep, kReuseGravity);
  // Again from the same positions: the same A, on the kept factor (the factoring body factors).
  body->BeginStep(kReuseStep, kReuseGravity);
  factoring->BeginStep(kReuseStep, kReuseGravity);
  EXPECT_EQ(body->last_pcg_iterations(), 1);
  const VecX& exact = factoring->v_star();
  EXPECT_LT((body->v_star() - exact).norm(), 1e-13 * exact.norm());
}

TEST(FactorReuseTest, ConstraintSolvesAfterAReusedStepApplyThisStepsInverse) {
  auto body = MakeReuseCantilever(true);
  if (!BeginAStepOnTheKeptFactor(*body)) GTEST_SKIP() << "CHOLMOD is not reused";
  ASSERT_GT(body->last_pcg_iterations(), 0);
  ASSERT_FALSE(body->system().factor_is_current());
  // A (A^-1 b) = b on the free DOFs to round-off: the solve factored this step's A.
  const VecX b = MakeFreeDofRhs(*body);
  VecX x = b;
  body->SolveSystem(x);
  EXPECT_TRUE(body->system().factor_is_current());
  VecX Ax;
  body->ApplySystemMatrix(x, Ax);
  EXPECT_LT((Ax - b).norm(), 1e-10 * b.norm());
  // The next step, whose constraint solve is likely to need A^-1 again, factors directly.
  body->EndStep(kReuseStep);
  body->BeginStep(kReuseStep, kReuseGravity);
  EXPECT_EQ(body->last_pcg_iterations(), 0);
  EXPECT_TRUE(body->system().factor_is_current());
}

TEST(FactorReuseTest, ApproximateSolvesUseTheKeptFactorAndLeaveTheNextStepReusing) {
  auto body = MakeReuseCantilever(true);
  if (!BeginAStepOnTheKeptFactor(*body)) GTEST_SKIP() << "CHOLMOD is not reused";
  ASSERT_GT(body->last_pcg_iterations(), 0);
  const VecX b = MakeFreeDofRhs(*body);
  VecX approximate = b;
  body->SolveSystemApproximately(approximate);
  EXPECT_FALSE(body->system().factor_is_current()) << "no factorization of this step's A";
  // P^-1 b with an earlier step's factor: close to A^-1 b, not equal to it.
  VecX exact = b;
  body->SolveSystem(exact);
  const double gap = (approximate - exact).norm();
  EXPECT_GT(gap, 0.0);
  EXPECT_LT(gap, 0.1 * exact.norm());
  // A fresh body whose only solve is the approximate one keeps reusing its factor.
  auto other = MakeReuseCantilever(true);
  ASSERT_TRUE(BeginAStepOnTheKeptFactor(*other));
  ASSERT_GT(other->last_pcg_iterations(), 0);
  VecX y = b;
  other->SolveSystemApproximately(y);
  other->EndStep(kReuseStep);
  other->BeginStep(kReuseStep, kReuseGravity);
  EXPECT_GT(other->last_pcg_iterations(), 0);
}

TEST(FactorReuseTest, RestoredStateContinuesBitIdenticallyOnTheKeptFactor) {
  auto body = MakeReuseCantilever(true);
  auto run = [&](int steps) {
    for (int step = 0; step < steps; ++step) {
      body->BeginStep(kReuseStep, kReuseGravity);
      body->EndStep(kReuseStep);
    }
  };
  run(5);
  const DeformableBody::State saved = body->SaveState();
  run(5);
  const VecX first = body->x();
  const int first_iterations = body->last_pcg_iterations();
  run(7);  // the kept factor moves on
  body->RestoreState(saved);
  run(5);
  EXPECT_EQ(body->last_pcg_iterations(), first_iterations);
  EXPECT_EQ(0, std::memcmp(first.data(), body->x().data(), sizeof(double) * first.size()));
}

TEST(FactorReuseTest, OutOfRangeSettingsAreRejected) {
  DeformableBodySettings settings;
  settings.factor_reuse.min_refactor_cost = 0.0;
  EXPECT_THROW(settings.Validate(), InputError);
  settings.factor_reuse.min_refactor_cost = 8.0;
  settings.factor_reuse.pcg_tolerance = 1.0;
  EXPECT_THROW(settings.Validate(), InputError);
  settings.factor_reuse.pcg_tolerance = 1e-10;
  EXPECT_NO_THROW(settings.Validate());
}

}  // namespace
}  // namespace taut
