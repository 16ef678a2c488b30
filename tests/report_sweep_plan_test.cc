#include <gtest/gtest.h>

#include <map>

#include "demos/tools/report/sweep_plan.h"

namespace taut {
namespace {

// Expects InputError whose message contains `part`.
template <typename F>
void ExpectInputError(F f, const std::string& part) {
  try {
    f();
    ADD_FAILURE() << "no InputError; expected one mentioning '" << part << "'";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

// Lists parse with spaces around items; bad items are named with the option.
TEST(ReportSweepPlanTest, ParsesListsAndNamesBadItems) {
  EXPECT_EQ(ParsePositiveIntList("5, 10,400", "--pgs-sweeps"), (std::vector<int>{5, 10, 400}));
  EXPECT_EQ(ParsePositiveDoubleList("1e-2,0.5", "--tolerance-factors"),
            (std::vector<double>{1e-2, 0.5}));
  ExpectInputError([] { ParsePositiveIntList("5,,10", "--pgs-sweeps"); }, "empty item 2");
  ExpectInputError([] { ParsePositiveIntList("5,x", "--pgs-sweeps"); }, "'x'");
  ExpectInputError([] { ParsePositiveIntList("2.5", "--sqp-iterations"); }, "--sqp-iterations");
  ExpectInputError([] { ParsePositiveIntList("0", "--dt-divisors"); }, "'0'");
  ExpectInputError([] { ParsePositiveIntList("-3", "--dt-divisors"); }, "'-3'");
  ExpectInputError([] { ParsePositiveIntList("", "--dt-divisors"); }, "empty item 1");
  ExpectInputError([] { ParsePositiveDoubleList("1e-3,nan", "--tolerance-factors"); }, "'nan'");
  ExpectInputError([] { ParsePositiveDoubleList("0", "--tolerance-factors"); }, "'0'");
  ExpectInputError([] { ParsePositiveDoubleList("1e-3x", "--tolerance-factors"); }, "'1e-3x'");
}

// Each family changes only its own knob of the base settings (the SQP family also takes the
// tightest tolerance so that its cap binds, on both paths); the dt and default families keep the
// base settings. The PGS cap is swept on the dual path only, the Newton cap and the penalty on
// the primal path only.
TEST(ReportSweepPlanTest, EachFamilyChangesOnlyItsKnob) {
  const SqpSettings base;
  const SweepLists lists;
  const std::vector<SweepPoint> plan = MakeSweepPlan(lists, base);
  std::map<std::string, int> count;
  for (const SweepPoint& p : plan) {
    const SqpSettings& s = p.settings;
    const std::string solver = GetIslandSolverName(s.solver);
    ++count[p.family + ":" + solver];
    if (p.family == "default") {
      EXPECT_EQ(p.label, solver);
      EXPECT_EQ(CalcRunKey(p), CalcRunKey({"", "", 1, WithSolver(base, s.solver)}));
    } else if (p.family == "pgs") {
      EXPECT_EQ(std::to_string(s.pgs.max_sweeps), p.label);
      EXPECT_EQ(s.max_iterations, base.max_iterations);
      EXPECT_EQ(s.violation_tolerance, base.violation_tolerance);
    } else if (p.family == "newton") {
      EXPECT_EQ(std::to_string(s.primal.max_newton_iterations), p.label);
      EXPECT_EQ(s.primal.max_iterations, base.primal.max_iterations);
      EXPECT_EQ(s.primal.penalty_scale, base.primal.penalty_scale);
      EXPECT_EQ(s.violation_tolerance, base.violation_tolerance);
    } else if (p.family == "penalty") {
      EXPECT_EQ(FormatKnob(s.primal.penalty_scale), p.label);
      EXPECT_EQ(s.primal.max_newton_iterations, base.primal.max_newton_iterations);
      EXPECT_EQ(s.violation_tolerance, base.violation_tolerance);
    } else if (p.family == "sqp") {
      EXPECT_EQ(std::to_string(s.max_iterations), p.label);
      EXPECT_EQ(s.primal.max_iterations, s.max_iterations);
      EXPECT_NEAR(s.violation_tolerance, 1e-5, 1e-18);
      EXPECT_NEAR(s.stationarity_tolerance, 1e-4, 1e-16);
      EXPECT_EQ(s.pgs.max_sweeps, base.pgs.max_sweeps);
      EXPECT_EQ(s.primal.max_newton_iterations, base.primal.max_newton_iterations);
    } else if (p.family == "tol") {
      EXPECT_EQ(FormatKnob(s.violation_tolerance), p.label);
      EXPECT_NEAR(s.stationarity_tolerance, 10.0 * s.violation_tolerance, 1e-15);
      EXPECT_EQ(s.max_iterations, base.max_iterations);
      EXPECT_EQ(s.primal.max_iterations, base.primal.max_iterations);
    } else {
      ASSERT_EQ(p.family, "dt");
      EXPECT_EQ(CalcRunKey({p.family, p.label, 1, s}),
                CalcRunKey({"", "", 1, WithSolver(base, s.solver)}));
    }
    EXPECT_EQ(p.dt_divisor == 1, p.family != "dt" || p.label == "dt");
  }
  EXPECT_EQ(count["default:dual"], 1);
  EXPECT_EQ(count["default:primal"], 1);
  EXPECT_EQ(count["default:auto"], 1);
  EXPECT_EQ(count["pgs:dual"], 6);
  EXPECT_EQ(count["pgs:primal"], 0);
  EXPECT_EQ(count["newton:primal"], 5);
  EXPECT_EQ(count["newton:dual"], 0);
  EXPECT_EQ(count["penalty:primal"], 4);
  for (const char* solver : {"dual", "primal"}) {
    EXPECT_EQ(count[std::string("sqp:") + solver], 5);
    EXPECT_EQ(count[std::string("tol:") + solver], 4);
    EXPECT_EQ(count[std::string("dt:") + solver], 3);
  }
  EXPECT_EQ(ListFamilies(plan),
            (std::vector<std::string>{"default", "pgs", "newton", "penalty", "sqp", "tol", "dt"}));
  const std::vector<SweepCurve> curves = ListCurves(plan);
  ASSERT_EQ(curves.size(), 3u + 1u + 2u + 2u * 3u);  // default x3, pgs, newton, penalty, rest x2
  EXPECT_EQ(curves[3].family, "pgs");
  EXPECT_EQ(curves[3].solver, "dual");
  EXPECT_EQ(curves[6].family, "sqp");
  EXPECT_EQ(curves[7].solver, "primal");
}

// Sweeping auto runs every family on it; --no-auto drops the auto default point.
TEST(ReportSweepPlanTest, SolverListChoosesThePaths) {
  SweepLists lists;
  lists.solvers = {IslandSolverKind::kAuto};
  std::map<std::string, int> count;
  for (const SweepPoint& p : MakeSweepPlan(lists, SqpSettings{})) {
    EXPECT_EQ(p.settings.solver, IslandSolverKind::kAuto);
    ++count[p.family];
  }
  EXPECT_EQ(count["default"], 1);
  EXPECT_EQ(count["pgs"], 6);
  EXPECT_EQ(count["newton"], 5);
  lists.solvers = {IslandSolverKind::kDual};
  lists.auto_default = false;
  for (const SweepPoint& p : MakeSweepPlan(lists, SqpSettings{}))
    EXPECT_EQ(p.settings.solver, IslandSolverKind::kDual) << p.family << " " << p.label;
  EXPECT_EQ(ParseSolverList("dual, primal,auto", "--solvers"),
            (std::vector<IslandSolverKind>{IslandSolverKind::kDual, IslandSolverKind::kPrimal,
                                           IslandSolverKind::kAuto}));
  ExpectInputError([] { ParseSolverList("dual,pgs", "--solvers"); }, "'pgs'");
  ExpectInputError([] { ParseSolverList("dual,dual", "--solvers"); }, "twice");
}

// Points that run identically share a key (the defaults appear in four families per path),
// others differ; a path's key ignores the other path's knobs.
TEST(ReportSweepPlanTest, RunKeysMatchOnlyIdenticalRuns) {
  const SqpSettings base;  // pgs.max_sweeps = 100, violation tolerance 1e-3, dt divisor 1
  std::map<std::string, std::vector<std::string>> by_key;
  for (const SweepPoint& p : MakeSweepPlan(SweepLists{}, base))
    by_key[CalcRunKey(p)].push_back(p.family + ":" + p.label + ":" +
                                    GetIslandSolverName(p.settings.solver));
  const SweepPoint dual{"", "", 1, WithSolver(base, IslandSolverKind::kDual)};
  EXPECT_EQ(by_key[CalcRunKey(dual)], (std::vector<std::string>{"default:dual:dual", "pgs:100:dual",
                                                                "tol:0.001:dual", "dt:dt:dual"}));
  const SweepPoint primal{"", "", 1, WithSolver(base, IslandSolverKind::kPrimal)};
  EXPECT_EQ(by_key[CalcRunKey(primal)],
            (std::vector<std::string>{"default:primal:primal", "newton:12:primal",
                                      "penalty:1000:primal", "tol:0.001:primal", "dt:dt:primal"}));
  // The SQP cap 10 at the tightest tolerance is the dual's tolerance-family 1e-5 point (the
  // primal's cap is 40, so not there).
  EXPECT_EQ(by_key[CalcRunKey({"", "", 1,
                               WithSolver(WithTolerance(base, 0.01 * base.violation_tolerance),
                                          IslandSolverKind::kDual)})],
            (std::vector<std::string>{"sqp:10:dual", "tol:1e-05:dual"}));
  // The dual path ignores the primal's knobs and the other way round.
  SweepPoint other = dual;
  other.settings.primal.max_newton_iterations = 3;
  EXPECT_EQ(CalcRunKey(other), CalcRunKey(dual));
  other = primal;
  other.settings.pgs.max_sweeps = 7;
  EXPECT_EQ(CalcRunKey(other), CalcRunKey(primal));
  other.settings.primal.penalty_scale = 7;
  EXPECT_NE(CalcRunKey(other), CalcRunKey(primal));
  EXPECT_NE(CalcRunKey(dual), CalcRunKey(primal));
  // Dual: 1 + 6 + 5 + 4 + 3 = 19 points in 15 runs (defaults x4, sqp:10 = tol:1e-05);
  // primal: 1 + 5 + 4 + 5 + 4 + 3 = 22 points in 18 runs (defaults x5); auto: 1.
  EXPECT_EQ(by_key.size(), 15u + 18u + 1u);
}

// A scene's own tolerance ratios survive: stationarity 100x violation stays 100x.
TEST(ReportSweepPlanTest, ToleranceKeepsTheBaseRatios) {
  SqpSettings base;
  base.violation_tolerance = 2e-3;
  base.stationarity_tolerance = 0.2;
  const SqpSettings s = WithTolerance(base, 1e-4);
  EXPECT_EQ(s.violation_tolerance, 1e-4);
  EXPECT_NEAR(s.stationarity_tolerance, 1e-2, 1e-15);
}

// Contact rows keep their weight in violation_after: the contact tolerance (when the settings
// have one) keeps its ratio to the violation tolerance.
TEST(ReportSweepPlanTest, ContactToleranceScalesWithViolationTolerance) {
  if constexpr (internal::HasContactTolerance<SqpSettings>::value) {
    const SqpSettings base;
    const SqpSettings tight = WithTolerance(base, 1e-5);
    EXPECT_EQ(tight.violation_tolerance, 1e-5);
    EXPECT_NEAR(tight.contact_tolerance / tight.violation_tolerance,
                base.contact_tolerance / base.violation_tolerance,
                1e-12 * base.contact_tolerance / base.violation_tolerance);
    EXPECT_LT(MakeReferenceSettings(base).contact_tolerance, tight.contact_tolerance);
  } else {
    GTEST_SKIP() << "SqpSettings has no contact_tolerance";
  }
}

// Tolerances follow the scene's own: a scene at 1e-5 sweeps 1e-4 ... 1e-7, on each path.
TEST(ReportSweepPlanTest, TolerancesAreRelativeToTheScene) {
  SqpSettings base;
  base.violation_tolerance = 1e-5;
  std::map<std::string, std::vector<std::string>> labels;
  for (const SweepPoint& p : MakeSweepPlan(SweepLists{}, base))
    if (p.family == "tol") labels[GetIslandSolverName(p.settings.solver)].push_back(p.label);
  ASSERT_EQ(labels.size(), 2u);
  for (const auto& [solver, list] : labels)
    EXPECT_EQ(list, (std::vector<std::string>{"0.0001", "1e-05", "1e-06", "1e-07"})) << solver;
}

// The reference is at least as tight as every sweep point, for the default and a tight scene.
TEST(ReportSweepPlanTest, ReferenceIsTighterThanTheSweep) {
  SqpSettings tight_scene;
  tight_scene.violation_tolerance = 1e-5;
  tight_scene.stationarity_tolerance = 1e-3;
  for (const SqpSettings& base : {SqpSettings{}, tight_scene}) {
    const SqpSettings ref = MakeReferenceSettings(base);
    EXPECT_EQ(ref.solver, IslandSolverKind::kPrimal);
    EXPECT_EQ(MakeReferenceSettings(base, IslandSolverKind::kDual).solver, IslandSolverKind::kDual);
    for (const SweepPoint& p : MakeSweepPlan(SweepLists{}, base)) {
      EXPECT_GE(ref.max_iterations, p.settings.max_iterations) << p.family << " " << p.label;
      EXPECT_GE(ref.pgs.max_sweeps, p.settings.pgs.max_sweeps) << p.family << " " << p.label;
      EXPECT_GE(ref.primal.max_iterations, p.settings.primal.max_iterations) << p.family;
      EXPECT_GE(ref.primal.max_newton_iterations, p.settings.primal.max_newton_iterations)
          << p.family << " " << p.label;
      EXPECT_LT(ref.violation_tolerance, p.settings.violation_tolerance);
      EXPECT_LT(ref.stationarity_tolerance, p.settings.stationarity_tolerance);
      EXPECT_LT(ref.pgs.tolerance, p.settings.pgs.tolerance);
    }
  }
  EXPECT_GT(SweepLists{}.reference_divisor, SweepLists{}.dt_divisors.back());
}

}  // namespace
}  // namespace taut
