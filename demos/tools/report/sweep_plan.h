// The solver settings that taut-report sweeps, and parsing of the lists that choose them.
//
// Header-only (inline) on purpose: tests/report_*_test.cc check this logic, and the tool's .cc
// files are linked only into taut-report, not into the test binary.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "constraints/sqp_solver.h"
#include "plugin/common.h"

namespace taut {

// One point of the sweep: which knob family it belongs to and the settings it runs with; the
// island solver path is settings.solver.
struct SweepPoint {
  std::string family;    // "default", "pgs", "newton", "penalty", "sqp", "tol", "dt", "reference"
  std::string label;     // the knob's value, e.g. "20" or "dt/2" ("default": the solver's name)
  int dt_divisor = 1;    // time step = scene dt / dt_divisor (same simulated time)
  SqpSettings settings;  // solver settings of the run
};

// The lists each family sweeps (each family varies one knob from the default settings), and the
// solver paths every family is swept with.
struct SweepLists {
  std::vector<int> pgs_sweeps = {5, 10, 20, 50, 100, 400};     // pgs.max_sweeps (dual path)
  std::vector<int> sqp_iterations = {1, 2, 4, 10, 20};         // SQP cap (tightest tolerance)
  std::vector<double> tolerance_factors = {10, 1, 0.1, 0.01};  // x the scene's tolerances
  std::vector<int> dt_divisors = {1, 2, 4};                    // dt / divisor, default solver
  int reference_divisor = 8;                                   // reference run: dt / this
  // Primal path: its stand-ins for the PGS cap, which it does not use.
  std::vector<int> newton_iterations = {1, 2, 4, 12, 30};    // primal.max_newton_iterations
  std::vector<double> penalty_scales = {10, 100, 1e3, 1e4};  // primal.penalty_scale
  // Paths swept through every family (kDual: pgs; kPrimal: newton, penalty; kAuto: all of
  // them), and whether a kAuto run at the default settings is added when kAuto is not swept.
  std::vector<IslandSolverKind> solvers = {IslandSolverKind::kDual, IslandSolverKind::kPrimal};
  bool auto_default = true;
  IslandSolverKind reference_solver = IslandSolverKind::kPrimal;  // path of the reference run
};

namespace internal {
// Splits "a,b,c" at commas (spaces around items are dropped); an empty item throws InputError.
inline std::vector<std::string> SplitList(const std::string& text, const std::string& what) {
  std::vector<std::string> items;
  std::string item;
  for (size_t i = 0; i <= text.size(); ++i) {
    if (i < text.size() && text[i] != ',') {
      if (text[i] != ' ') item += text[i];
      continue;
    }
    TAUT_DEMAND(!item.empty(), what, ": empty item ", items.size() + 1, " in '", text, "'");
    items.push_back(item);
    item.clear();
  }
  return items;
}
}  // namespace internal

// Parses "5,10,20" into positive integers; throws InputError naming `what` and the bad item.
inline std::vector<int> ParsePositiveIntList(const std::string& text, const std::string& what) {
  std::vector<int> values;
  for (const std::string& item : internal::SplitList(text, what)) {
    size_t used = 0;
    long value = 0;
    try {
      value = std::stol(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    TAUT_DEMAND(used == item.size() && value > 0 && value <= 1000000, what, ": item ",
                values.size() + 1, " '", item, "' of '", text, "' is not a positive integer");
    values.push_back(static_cast<int>(value));
  }
  return values;
}

// Parses "1e-2,1e-3" into finite positive numbers; throws InputError naming the bad item.
inline std::vector<double> ParsePositiveDoubleList(const std::string& text,
                                                   const std::string& what) {
  std::vector<double> values;
  for (const std::string& item : internal::SplitList(text, what)) {
    size_t used = 0;
    double value = 0.0;
    try {
      value = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    TAUT_DEMAND(used == item.size() && std::isfinite(value) && value > 0.0, what, ": item ",
                values.size() + 1, " '", item, "' of '", text, "' is not a positive number");
    values.push_back(value);
  }
  return values;
}

// Parses "dual,primal,auto" into solver kinds (no repeats); throws InputError naming the bad item.
inline std::vector<IslandSolverKind> ParseSolverList(const std::string& text,
                                                     const std::string& what) {
  std::vector<IslandSolverKind> kinds;
  for (const std::string& item : internal::SplitList(text, what)) {
    IslandSolverKind kind = IslandSolverKind::kAuto;
    if (item == "dual")
      kind = IslandSolverKind::kDual;
    else if (item == "primal")
      kind = IslandSolverKind::kPrimal;
    else
      TAUT_DEMAND(item == "auto", what, ": item ", kinds.size() + 1, " '", item, "' of '", text,
                  "' is not dual, primal or auto");
    TAUT_DEMAND(std::find(kinds.begin(), kinds.end(), kind) == kinds.end(), what, ": '", item,
                "' appears twice in '", text, "'");
    kinds.push_back(kind);
  }
  return kinds;
}

// Short text of a number for labels: 1e-05 -> "1e-05", 20 -> "20".
inline std::string FormatKnob(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%g", value);
  return text;
}

namespace internal {
// Whether the settings have a separate contact tolerance (in m).
template <typename T, typename = void>
struct HasContactTolerance : std::false_type {};
template <typename T>
struct HasContactTolerance<T, std::void_t<decltype(std::declval<T>().contact_tolerance)>>
    : std::true_type {};

// Multiplies the contact tolerance, where the settings have one, by `factor`.
template <typename T>
void ScaleContactTolerance(T& s, double factor) {
  if constexpr (HasContactTolerance<T>::value) s.contact_tolerance *= factor;
}
}  // namespace internal

// Settings with violation tolerance `tol`; the stationarity tolerance and a contact tolerance
// (where the settings have one) scale by the same factor, so their ratios stay the base's (contact
// rows then weigh the same in violation_after, which scales them by violation / contact tolerance).
inline SqpSettings WithTolerance(SqpSettings s, double tol) {
  const double factor = s.violation_tolerance > 0.0 ? tol / s.violation_tolerance : 1.0;
  internal::ScaleContactTolerance(s, factor);
  s.stationarity_tolerance *= factor;
  s.violation_tolerance = tol;
  return s;
}

// Factor of the reference run's tolerances over the scene's (1e-3 -> 1e-6 for the defaults).
constexpr double kReferenceToleranceFactor = 1e-3;

// Tight settings of the reference run: small tolerances, caps at least the default sweep's (both
// paths), on the path `solver`.
inline SqpSettings MakeReferenceSettings(const SqpSettings& base,
                                         IslandSolverKind solver = IslandSolverKind::kPrimal) {
  SqpSettings s = WithTolerance(base, kReferenceToleranceFactor * base.violation_tolerance);
  s.solver = solver;
  s.max_iterations = 20;
  s.max_restoration_iterations = 20;
  s.pgs.max_sweeps = 400;
  s.pgs.tolerance = 1e-7;
  s.primal.max_iterations = std::max(80, base.primal.max_iterations);
  s.primal.max_newton_iterations = std::max(30, base.primal.max_newton_iterations);
  return s;
}

// Whether a path uses the dual (PGS) or the primal (Newton) knobs.
inline bool UsesDualKnobs(IslandSolverKind kind) { return kind != IslandSolverKind::kPrimal; }
inline bool UsesPrimalKnobs(IslandSolverKind kind) { return kind != IslandSolverKind::kDual; }

// The base settings on path `kind`.
inline SqpSettings WithSolver(SqpSettings s, IslandSolverKind kind) {
  s.solver = kind;
  return s;
}

// Every sweep point: first one "default" point per path (base settings; label = the path's
// name), then family by family (pgs, newton, penalty, sqp, tol, dt), within a family path by path
// in the order of lists.solvers, each in the order of its list (increasing effort when the lists
// are sorted). The PGS cap is swept on paths that run PGS, the Newton cap and the penalty scale
// on paths that run Newton. Tolerances are the base's times the factors; the SQP family uses the
// tightest of them (or the base's) so that its cap binds, and sets the SQP cap of both paths.
inline std::vector<SweepPoint> MakeSweepPlan(const SweepLists& lists, const SqpSettings& base) {
  std::vector<SweepPoint> plan;
  std::vector<IslandSolverKind> defaults = lists.solvers;
  if (lists.auto_default &&
      std::find(defaults.begin(), defaults.end(), IslandSolverKind::kAuto) == defaults.end())
    defaults.push_back(IslandSolverKind::kAuto);
  for (IslandSolverKind kind : defaults)
    plan.push_back({"default", GetIslandSolverName(kind), 1, WithSolver(base, kind)});
  for (IslandSolverKind kind : lists.solvers) {
    if (!UsesDualKnobs(kind)) continue;
    for (int sweeps : lists.pgs_sweeps) {
      SweepPoint p{"pgs", std::to_string(sweeps), 1, WithSolver(base, kind)};
      p.settings.pgs.max_sweeps = sweeps;
      plan.push_back(p);
    }
  }
  for (IslandSolverKind kind : lists.solvers) {
    if (!UsesPrimalKnobs(kind)) continue;
    for (int iterations : lists.newton_iterations) {
      SweepPoint p{"newton", std::to_string(iterations), 1, WithSolver(base, kind)};
      p.settings.primal.max_newton_iterations = iterations;
      plan.push_back(p);
    }
  }
  for (IslandSolverKind kind : lists.solvers) {
    if (!UsesPrimalKnobs(kind)) continue;
    for (double scale : lists.penalty_scales) {
      SweepPoint p{"penalty", FormatKnob(scale), 1, WithSolver(base, kind)};
      p.settings.primal.penalty_scale = scale;
      plan.push_back(p);
    }
  }
  double tightest = base.violation_tolerance;
  for (double f : lists.tolerance_factors)
    tightest = std::min(tightest, f * base.violation_tolerance);
  for (IslandSolverKind kind : lists.solvers)
    for (int iterations : lists.sqp_iterations) {
      SweepPoint p{"sqp", std::to_string(iterations), 1,
                   WithSolver(WithTolerance(base, tightest), kind)};
      p.settings.max_iterations = iterations;
      p.settings.primal.max_iterations = iterations;
      plan.push_back(p);
    }
  for (IslandSolverKind kind : lists.solvers)
    for (double f : lists.tolerance_factors) {
      const double tol = f * base.violation_tolerance;
      plan.push_back({"tol", FormatKnob(tol), 1, WithSolver(WithTolerance(base, tol), kind)});
    }
  for (IslandSolverKind kind : lists.solvers)
    for (int divisor : lists.dt_divisors)
      plan.push_back({"dt", divisor == 1 ? "dt" : "dt/" + std::to_string(divisor), divisor,
                      WithSolver(base, kind)});
  return plan;
}

// A key equal for two points that would run identically: same path, dt and the knobs the plan
// sets that the path reads (the dual path ignores the primal's, and the other way round).
inline std::string CalcRunKey(const SweepPoint& p) {
  const SqpSettings& s = p.settings;
  char key[320];
  int n = std::snprintf(key, sizeof(key), "%s|%d|%.17g|%.17g|%.17g", GetIslandSolverName(s.solver),
                        p.dt_divisor, s.violation_tolerance, s.stationarity_tolerance,
                        s.contact_tolerance);
  if (UsesDualKnobs(s.solver))
    n += std::snprintf(key + n, sizeof(key) - n, "|d%d|%d|%d|%.17g", s.max_iterations,
                       s.max_restoration_iterations, s.pgs.max_sweeps, s.pgs.tolerance);
  if (UsesPrimalKnobs(s.solver))
    std::snprintf(key + n, sizeof(key) - n, "|p%d|%d|%.17g", s.primal.max_iterations,
                  s.primal.max_newton_iterations, s.primal.penalty_scale);
  return key;
}

// The (family, solver) curves of a plan in first-appearance order.
struct SweepCurve {
  std::string family;
  std::string solver;  // GetIslandSolverName
  bool operator==(const SweepCurve& o) const { return family == o.family && solver == o.solver; }
};
inline std::vector<SweepCurve> ListCurves(const std::vector<SweepPoint>& plan) {
  std::vector<SweepCurve> curves;
  for (const SweepPoint& p : plan) {
    const SweepCurve c{p.family, GetIslandSolverName(p.settings.solver)};
    if (std::find(curves.begin(), curves.end(), c) == curves.end()) curves.push_back(c);
  }
  return curves;
}

// Families of a plan in first-appearance order.
inline std::vector<std::string> ListFamilies(const std::vector<SweepPoint>& plan) {
  std::vector<std::string> families;
  std::set<std::string> seen;
  for (const SweepPoint& p : plan)
    if (seen.insert(p.family).second) families.push_back(p.family);
  return families;
}

}  // namespace taut
