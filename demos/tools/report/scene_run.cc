#include "demos/tools/report/scene_run.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <string>
#include <type_traits>
#include <utility>

#include "demos/tools/report/figure_search.h"

namespace taut {

namespace {

using Clock = std::chrono::steady_clock;

// CPU time of the calling thread [ms]: the cost of a step even when other processes share the
// cores (wall time then includes waiting).
double ReadThreadCpuMs() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
}

// StepStats fields that newer solver versions add: read when present, NaN otherwise, so the
// report fills the column as soon as the field exists.
template <typename T, typename = void>
struct HasLcpResidual : std::false_type {};
template <typename T>
struct HasLcpResidual<T, std::void_t<decltype(std::declval<T>().lcp_residual)>> : std::true_type {};
template <typename T, typename = void>
struct HasMaxPenetration : std::false_type {};
template <typename T>
struct HasMaxPenetration<T, std::void_t<decltype(std::declval<T>().max_penetration)>>
    : std::true_type {};

// Natural-map residual of the step's last QP, NaN when StepStats does not carry it.
template <typename T>
double ReadLcpResidual(const T& stats) {
  if constexpr (HasLcpResidual<T>::value) {
    return stats.lcp_residual;
  } else {
    return ReportRow::kNaN;
  }
}

// Deepest contact penetration at the end of the step [m], NaN when StepStats does not carry it.
template <typename T>
double ReadMaxPenetration(const T& stats) {
  if constexpr (HasMaxPenetration<T>::value) {
    return stats.max_penetration;
  } else {
    return ReportRow::kNaN;
  }
}

// Free-node positions of every deformable body.
TrajectorySample SampleFreeNodes(const Scene& scene) {
  TrajectorySample sample;
  for (int b = 0; b < scene.world().num_deformable_bodies(); ++b) {
    const DeformableBody& body = scene.world().deformable_body(b);
    int free = 0;
    for (int i = 0; i < body.num_nodes(); ++i) free += body.node_kind(i) == NodeKind::kFree;
    VecX x(3 * free);
    for (int i = 0, k = 0; i < body.num_nodes(); ++i)
      if (body.node_kind(i) == NodeKind::kFree) x.segment<3>(3 * k++) = body.node_position(i);
    sample.push_back(std::move(x));
  }
  return sample;
}

// Running sums of the per-step statistics.
struct StepTally {
  int steps = 0, unconverged = 0, constrained_steps = 0;
  double sqp = 0.0, sweeps = 0.0, newton = 0.0, pcg = 0.0, stationarity_sum = 0.0;
  double islands_dual = 0.0, islands_primal = 0.0;
  double max_violation = 0.0, max_stationarity = 0.0;
  double max_kkt_primal = 0.0, max_kkt_complementarity = 0.0, max_kkt_dual = 0.0;
  double max_lcp = ReportRow::kNaN, max_penetration = ReportRow::kNaN;
  bool any_contact = false;

  // Adds one step's statistics.
  void Add(const StepStats& s) {
    ++steps;
    unconverged += s.converged ? 0 : 1;
    sqp += s.sqp_iterations;
    sweeps += s.pgs_sweeps;
    newton += s.newton_iterations;
    pcg += s.pcg_iterations;
    islands_dual += s.islands_dual;
    islands_primal += s.islands_primal;
    max_violation = std::max(max_violation, s.violation_after);
    if (s.rows_total() > 0) {
      ++constrained_steps;
      stationarity_sum += s.stationarity;
      max_stationarity = std::max(max_stationarity, s.stationarity);
      max_kkt_primal = std::max(max_kkt_primal, s.kkt_primal);
      max_kkt_complementarity = std::max(max_kkt_complementarity, s.kkt_complementarity);
      max_kkt_dual = std::max(max_kkt_dual, s.kkt_dual);
      // The natural-map residual is the dual path's (its last QP); the primal path has no QP.
      if (s.islands_dual > 0) max_lcp = MaxOfKnown(max_lcp, ReadLcpResidual(s));
    }
    if (s.rows_contact > 0) any_contact = true;
    max_penetration = MaxOfKnown(max_penetration, ReadMaxPenetration(s));
  }
};

// Short text of an exception for the status column.
std::string Shorten(const std::string& text) {
  return text.size() <= 80 ? text : text.substr(0, 77) + "...";
}

}  // namespace

bool StepStatsHaveLcpResidual() { return HasLcpResidual<StepStats>::value; }

std::vector<double> CalcBodyLengths(const Scene& scene) {
  std::vector<double> lengths;
  for (int b = 0; b < scene.world().num_deformable_bodies(); ++b)
    lengths.push_back(
        CalcBoundingBoxDiagonal(scene.world().deformable_body(b).model().rest_positions()));
  return lengths;
}

RunOutcome RunSweepPoint(const SceneInfo& info, const SweepPoint& point, const RunPlan& plan,
                         const ReferenceTrajectory* reference) {
  std::unique_ptr<Scene> scene = info.make();
  scene->world().mutable_solver_settings() = point.settings;
  const double h = plan.dt / point.dt_divisor;
  const int steps_per_sample = plan.frame_steps * point.dt_divisor;
  RunOutcome out;
  ReportRow& row = out.row;
  row.family = point.family;
  row.label = point.label;
  row.solver = GetIslandSolverName(point.settings.solver);
  row.dt = h;
  row.pgs_max_sweeps = point.settings.pgs.max_sweeps;
  row.sqp_max_iterations = point.settings.max_iterations;
  row.primal_max_iterations = point.settings.primal.max_iterations;
  row.newton_max_iterations = point.settings.primal.max_newton_iterations;
  row.penalty_scale = point.settings.primal.penalty_scale;
  row.violation_tolerance = point.settings.violation_tolerance;
  row.stationarity_tolerance = point.settings.stationarity_tolerance;
  StepTally tally;
  std::vector<double> ms_steps, ms_frames, errors;
  int unlike_samples = 0;  // samples whose bodies differ from the reference's
  const auto start = Clock::now();
  double ms_frame = 0.0, cpu_ms_total = 0.0, cpu_ms_sample = 0.0;
  try {
    for (int k = 1; k <= plan.samples; ++k) {
      cpu_ms_sample = 0.0;
      for (int i = 0; i < steps_per_sample; ++i) {
        const auto t0 = Clock::now();
        const double cpu0 = ReadThreadCpuMs();
        scene->Simulate(h);  // timed: the simulation only
        cpu_ms_sample += ReadThreadCpuMs() - cpu0;
        const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
        scene->Measure(h);  // the scene's own figures, outside the timer
        ms_steps.push_back(ms);
        ms_frame += ms;
        tally.Add(scene->world().last_step_stats());
      }
      cpu_ms_total += cpu_ms_sample;
      ms_frames.push_back(ms_frame);
      ms_frame = 0.0;
      out.samples.push_back(SampleFreeNodes(*scene));
      out.lengths.push_back(CalcBodyLengths(*scene));
      out.completed_samples = k;
      if (reference != nullptr && k <= static_cast<int>(reference->samples.size())) {
        const TrajectorySample& ref = reference->samples[k - 1];
        if (HaveSameLayout(out.samples.back(), ref))
          errors.push_back(
              CalcNormalizedRmsDistance(out.samples.back(), ref, reference->lengths[k - 1]));
        else
          ++unlike_samples;
      }
      // Stop before a sample that would likely end past the budget (as long as the last one);
      // the budget counts CPU time, so that a busy machine does not shorten the run.
      if (plan.cpu_budget_s > 0.0 && 1e-3 * (cpu_ms_total + cpu_ms_sample) > plan.cpu_budget_s &&
          k < plan.samples) {
        row.status = internal::Concat("timeout at t = ", k * plan.frame_steps * plan.dt, " s");
        break;
      }
    }
  } catch (const std::exception& e) {
    row.status =
        internal::Concat("failed at t = ", (tally.steps + 1) * h, " s: ", Shorten(e.what()));
  }
  // Cost: medians over steps and over complete sample intervals, scaled to a 1/60 s frame.
  row.steps = tally.steps;
  row.wall_s = std::chrono::duration<double>(Clock::now() - start).count();
  row.ms_step = CalcMedian(ms_steps);
  const double frame_scale = (1.0 / 60.0) / (plan.frame_steps * plan.dt);  // sample -> frame
  row.ms_frame = CalcMedian(ms_frames) * frame_scale;
  double ms_total = 0.0;
  for (double ms : ms_steps) ms_total += ms;
  if (tally.steps > 0) {
    row.ms_frame_mean = ms_total / (tally.steps * h) * (1.0 / 60.0);
    row.cpu_ms_frame_mean = cpu_ms_total / (tally.steps * h) * (1.0 / 60.0);
    row.mean_sqp_iterations = tally.sqp / tally.steps;
    row.mean_pgs_sweeps = tally.sweeps / tally.steps;
    row.mean_newton_iterations = tally.newton / tally.steps;
    row.mean_pcg_iterations = tally.pcg / tally.steps;
  }
  if (tally.islands_dual + tally.islands_primal > 0)
    row.primal_island_share = tally.islands_primal / (tally.islands_dual + tally.islands_primal);
  row.unconverged_steps = tally.unconverged;
  row.max_violation = tally.max_violation;
  row.max_stationarity = tally.max_stationarity;
  row.mean_stationarity =
      tally.constrained_steps > 0 ? tally.stationarity_sum / tally.constrained_steps : 0.0;
  row.max_lcp_residual = tally.max_lcp;
  if (tally.constrained_steps > 0) {
    row.max_kkt_primal = tally.max_kkt_primal;
    row.max_kkt_complementarity = tally.max_kkt_complementarity;
    row.max_kkt_dual = tally.max_kkt_dual;
  }
  // Energy ratio and penetration: the scene's own run maxima, and the step statistics' depth.
  nlohmann::json figures;
  scene->WriteFigures(figures);
  row.max_energy_ratio = FindMaxEnergyRatio(figures);
  row.max_penetration = FindMaxPenetration(figures);
  if (tally.any_contact)
    row.max_penetration = MaxOfKnown(row.max_penetration, tally.max_penetration);
  if (reference != nullptr && !errors.empty()) {
    row.traj_error_rms = CalcRms(errors);
    row.traj_error_end = errors.back();
  }
  if (unlike_samples > 0)
    row.status += internal::Concat("; ", unlike_samples, " of ", out.completed_samples,
                                   " samples had other bodies than the reference");
  return out;
}

}  // namespace taut
