// Range checks of the island solvers' settings (constraints/sqp_settings.h).
#include "constraints/sqp_settings.h"

#include <cmath>
#include <string>

namespace taut {
namespace {

// Each check throws InputError "SqpSettings::<field> = <value> must be <range>".
void DemandPositive(const char* field, double value) {
  TAUT_DEMAND(std::isfinite(value) && value > 0.0, "SqpSettings::", field, " = ", value,
              " must be finite and > 0");
}

void DemandNonNegative(const char* field, double value) {
  TAUT_DEMAND(std::isfinite(value) && value >= 0.0, "SqpSettings::", field, " = ", value,
              " must be finite and >= 0");
}

void DemandAtLeast(const char* field, double value, double minimum) {
  TAUT_DEMAND(std::isfinite(value) && value >= minimum, "SqpSettings::", field, " = ", value,
              " must be finite and >= ", minimum);
}

void DemandCount(const char* field, int value, int minimum) {
  TAUT_DEMAND(value >= minimum, "SqpSettings::", field, " = ", value, " must be >= ", minimum);
}

// lo < value <= hi (lo_open) or lo <= value < hi (hi_open).
void DemandInterval(const char* field, double value, double lo, double hi, const char* range,
                    bool lo_open) {
  const bool inside = lo_open ? value > lo && value <= hi : value >= lo && value < hi;
  TAUT_DEMAND(inside, "SqpSettings::", field, " = ", value, " must be in ", range);
}

void ValidatePrimalSettings(const PrimalSettings& p) {
  DemandCount("primal.max_iterations", p.max_iterations, 1);
  DemandCount("primal.max_newton_iterations", p.max_newton_iterations, 1);
  DemandPositive("primal.penalty_scale", p.penalty_scale);
  DemandAtLeast("primal.penalty_growth", p.penalty_growth, 1.0);
  DemandAtLeast("primal.max_penalty_growth", p.max_penalty_growth, 1.0);
  DemandNonNegative("primal.newton_tolerance", p.newton_tolerance);
  DemandNonNegative("primal.newton_row_move_fraction", p.newton_row_move_fraction);
  DemandNonNegative("primal.newton_stop_distance_factor", p.newton_stop_distance_factor);
  DemandInterval("primal.newton_stall_fraction", p.newton_stall_fraction, 0.0, 1.0, "[0, 1)",
                 false);
  DemandNonNegative("primal.newton_stall_decrement", p.newton_stall_decrement);
  DemandCount("primal.newton_stall_iterations", p.newton_stall_iterations, 0);
  DemandCount("primal.max_pcg_iterations", p.max_pcg_iterations, 1);
  DemandInterval("primal.pcg_tolerance", p.pcg_tolerance, 0.0, 1.0, "(0, 1]", true);
  DemandCount("primal.max_model_steps", p.max_model_steps, 0);
  DemandInterval("primal.model_step_alpha", p.model_step_alpha, 0.0, 1.0, "(0, 1]", true);
  DemandCount("primal.model_pcg_iterations", p.model_pcg_iterations, 1);
  DemandNonNegative("primal.min_refactor_cost", p.min_refactor_cost);
  DemandInterval("primal.stale_pcg_tolerance", p.stale_pcg_tolerance, 0.0, 1.0, "(0, 1]", true);
}

void ValidatePolishSettings(const ActiveSetPolishSettings& polish) {
  DemandCount("polish.max_rounds", polish.max_rounds, 0);
  DemandCount("polish.sweeps_per_round", polish.sweeps_per_round, 0);
  DemandNonNegative("polish.tolerance", polish.tolerance);
  DemandNonNegative("polish.regularization", polish.regularization);
}

}  // namespace

void ValidateSqpSettings(const SqpSettings& s) {
  DemandCount("max_iterations", s.max_iterations, 1);
  DemandPositive("violation_tolerance", s.violation_tolerance);
  DemandPositive("contact_tolerance", s.contact_tolerance);
  DemandPositive("stationarity_tolerance", s.stationarity_tolerance);
  DemandCount("max_restoration_iterations", s.max_restoration_iterations, 0);
  DemandCount("max_line_search_halvings", s.max_line_search_halvings, 0);
  DemandAtLeast("full_step_violation_factor", s.full_step_violation_factor, 1.0);
  DemandCount("max_row_discovery_passes", s.max_row_discovery_passes, 0);
  DemandInterval("stalled_step", s.stalled_step, 0.0, 1.0, "[0, 1)", false);
  try {
    ValidatePgsSettings(s.pgs);
  } catch (const InputError& e) {
    throw InputError(std::string("SqpSettings::pgs: ") + e.what());
  }
  ValidatePolishSettings(s.polish);
  DemandNonNegative("warm_stop_distance_factor", s.warm_stop_distance_factor);
  const int solver = static_cast<int>(s.solver);
  TAUT_DEMAND(solver >= static_cast<int>(IslandSolverKind::kAuto) &&
                  solver <= static_cast<int>(IslandSolverKind::kPrimal),
              "SqpSettings::solver = ", solver, " is not an IslandSolverKind");
  ValidatePrimalSettings(s.primal);
  DemandCount("retry_max_iterations", s.retry_max_iterations, 1);
}

}  // namespace taut
