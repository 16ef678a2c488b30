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

void DemandAtLeast(const char* field, double value, double minimum) {
  TAUT_DEMAND(std::isfinite(value) && value >= minimum, "SqpSettings::", field, " = ", value,
              " must be finite and >= ", minimum);
}

void DemandCount(const char* field, int value, int minimum) {
  TAUT_DEMAND(value >= minimum, "SqpSettings::", field, " = ", value, " must be >= ", minimum);
}

// A fraction in (0, 1] (a relative tolerance, a step length).
void DemandFraction(const char* field, double value) {
  TAUT_DEMAND(value > 0.0 && value <= 1.0, "SqpSettings::", field, " = ", value,
              " must be in (0, 1]");
}

// A share in [0, 1) (0 = off).
void DemandShare(const char* field, double value) {
  TAUT_DEMAND(value >= 0.0 && value < 1.0, "SqpSettings::", field, " = ", value,
              " must be in [0, 1)");
}

void ValidatePrimalSettings(const PrimalSettings& p) {
  DemandCount("primal.max_iterations", p.max_iterations, 1);
  DemandCount("primal.max_newton_iterations", p.max_newton_iterations, 1);
  DemandPositive("primal.penalty_scale", p.penalty_scale);
  DemandAtLeast("primal.penalty_growth", p.penalty_growth, 1.0);
  DemandAtLeast("primal.max_penalty_growth", p.max_penalty_growth, 1.0);
  DemandCount("primal.late_growth_iteration", p.late_growth_iteration, 0);
  DemandAtLeast("primal.late_max_penalty_growth", p.late_max_penalty_growth, 1.0);
  DemandAtLeast("primal.newton_tolerance", p.newton_tolerance, 0.0);
  DemandAtLeast("primal.newton_row_move_fraction", p.newton_row_move_fraction, 0.0);
  DemandAtLeast("primal.newton_stop_distance_factor", p.newton_stop_distance_factor, 0.0);
  DemandShare("primal.newton_stall_fraction", p.newton_stall_fraction);
  DemandAtLeast("primal.newton_stall_decrement", p.newton_stall_decrement, 0.0);
  DemandCount("primal.newton_stall_iterations", p.newton_stall_iterations, 0);
  DemandCount("primal.max_pcg_iterations", p.max_pcg_iterations, 1);
  DemandFraction("primal.pcg_tolerance", p.pcg_tolerance);
  DemandCount("primal.max_model_steps", p.max_model_steps, 0);
  DemandFraction("primal.model_step_alpha", p.model_step_alpha);
  DemandCount("primal.model_pcg_iterations", p.model_pcg_iterations, 1);
  DemandAtLeast("primal.min_refactor_cost", p.min_refactor_cost, 0.0);
  DemandFraction("primal.stale_pcg_tolerance", p.stale_pcg_tolerance);
}

void ValidatePolishSettings(const ActiveSetPolishSettings& polish) {
  DemandCount("polish.max_rounds", polish.max_rounds, 0);
  DemandCount("polish.sweeps_per_round", polish.sweeps_per_round, 0);
  DemandAtLeast("polish.tolerance", polish.tolerance, 0.0);
  DemandAtLeast("polish.regularization", polish.regularization, 0.0);
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
  DemandShare("stalled_step", s.stalled_step);
  try {
    ValidatePgsSettings(s.pgs);
  } catch (const InputError& e) {
    throw InputError(std::string("SqpSettings::pgs: ") + e.what());
  }
  ValidatePolishSettings(s.polish);
  DemandAtLeast("warm_stop_distance_factor", s.warm_stop_distance_factor, 0.0);
  const int solver = static_cast<int>(s.solver);
  TAUT_DEMAND(solver >= static_cast<int>(IslandSolverKind::kAuto) &&
                  solver <= static_cast<int>(IslandSolverKind::kPrimal),
              "SqpSettings::solver = ", solver, " is not an IslandSolverKind");
  ValidatePrimalSettings(s.primal);
  DemandCount("retry_max_iterations", s.retry_max_iterations, 1);
}

}  // namespace taut
