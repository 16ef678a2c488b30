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
// tightest tolerance so that its cap binds); the dt family keeps the base settings.
TEST(ReportSweepPlanTest, EachFamilyChangesOnlyItsKnob) {
  const SqpSettings base;
  const SweepLists lists;
  const std::vector<SweepPoint> plan = MakeSweepPlan(lists, base);
  std::map<std::string, int> count;
  for (const SweepPoint& p : plan) {
    ++count[p.family];
    const SqpSettings& s = p.settings;
    if (p.family == "pgs") {
      EXPECT_EQ(std::to_string(s.pgs.max_sweeps), p.label);
      EXPECT_EQ(s.max_iterations, base.max_iterations);
      EXPECT_EQ(s.violation_tolerance, base.violation_tolerance);
    } else if (p.family == "sqp") {
      EXPECT_EQ(std::to_string(s.max_iterations), p.label);
      EXPECT_NEAR(s.violation_tolerance, 1e-5, 1e-18);
      EXPECT_NEAR(s.stationarity_tolerance, 1e-4, 1e-16);
      EXPECT_EQ(s.pgs.max_sweeps, base.pgs.max_sweeps);
    } else if (p.family == "tol") {
      EXPECT_EQ(FormatKnob(s.violation_tolerance), p.label);
      EXPECT_NEAR(s.stationarity_tolerance, 10.0 * s.violation_tolerance, 1e-15);
      EXPECT_EQ(s.max_iterations, base.max_iterations);
    } else {
      ASSERT_EQ(p.family, "dt");
      EXPECT_EQ(CalcRunKey({p.family, p.label, 1, s}), CalcRunKey({"", "", 1, base}));
    }
    EXPECT_EQ(p.dt_divisor == 1, p.family != "dt" || p.label == "dt");
  }
  EXPECT_EQ(count["pgs"], 6);
  EXPECT_EQ(count["sqp"], 5);
  EXPECT_EQ(count["tol"], 4);
  EXPECT_EQ(count["dt"], 3);
  EXPECT_EQ(ListFamilies(plan), (std::vector<std::string>{"pgs", "sqp", "tol", "dt"}));
}

// Points that run identically share a key (the defaults appear in three families), others differ.
TEST(ReportSweepPlanTest, RunKeysMatchOnlyIdenticalRuns) {
  const SqpSettings base;  // pgs.max_sweeps = 100, violation tolerance 1e-3, dt divisor 1
  std::map<std::string, std::vector<std::string>> by_key;
  for (const SweepPoint& p : MakeSweepPlan(SweepLists{}, base))
    by_key[CalcRunKey(p)].push_back(p.family + ":" + p.label);
  const SweepPoint defaults{"", "", 1, base};
  EXPECT_EQ(by_key[CalcRunKey(defaults)],
            (std::vector<std::string>{"pgs:100", "tol:0.001", "dt:dt"}));
  // The SQP cap 10 at the tightest tolerance is the tolerance family's 1e-5 point.
  EXPECT_EQ(by_key[CalcRunKey({"", "", 1, WithTolerance(base, 0.01 * base.violation_tolerance)})],
            (std::vector<std::string>{"sqp:10", "tol:1e-05"}));
  // 18 points make 15 distinct runs.
  EXPECT_EQ(by_key.size(), 15u);
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

// Tolerances follow the scene's own: a scene at 1e-5 sweeps 1e-4 ... 1e-7.
TEST(ReportSweepPlanTest, TolerancesAreRelativeToTheScene) {
  SqpSettings base;
  base.violation_tolerance = 1e-5;
  std::vector<std::string> labels;
  for (const SweepPoint& p : MakeSweepPlan(SweepLists{}, base))
    if (p.family == "tol") labels.push_back(p.label);
  EXPECT_EQ(labels, (std::vector<std::string>{"0.0001", "1e-05", "1e-06", "1e-07"}));
}

// The reference is at least as tight as every sweep point, for the default and a tight scene.
TEST(ReportSweepPlanTest, ReferenceIsTighterThanTheSweep) {
  SqpSettings tight_scene;
  tight_scene.violation_tolerance = 1e-5;
  tight_scene.stationarity_tolerance = 1e-3;
  for (const SqpSettings& base : {SqpSettings{}, tight_scene}) {
    const SqpSettings ref = MakeReferenceSettings(base);
    for (const SweepPoint& p : MakeSweepPlan(SweepLists{}, base)) {
      EXPECT_GE(ref.max_iterations, p.settings.max_iterations) << p.family << " " << p.label;
      EXPECT_GE(ref.pgs.max_sweeps, p.settings.pgs.max_sweeps) << p.family << " " << p.label;
      EXPECT_LT(ref.violation_tolerance, p.settings.violation_tolerance);
      EXPECT_LT(ref.stationarity_tolerance, p.settings.stationarity_tolerance);
      EXPECT_LT(ref.pgs.tolerance, p.settings.pgs.tolerance);
    }
  }
  EXPECT_GT(SweepLists{}.reference_divisor, SweepLists{}.dt_divisors.back());
}

}  // namespace
}  // namespace taut
