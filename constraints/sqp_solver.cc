#include "constraints/sqp_solver.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "constraints/active_set_polish.h"
#include "constraints/deformable_island_body.h"
#include "constraints/kkt_certificate.h"

namespace taut {

namespace {
double MsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// ||dv||_A^2 = dv^T A dv summed over bodies (dv read on free DOFs).
double EnergyNormSquared(const std::vector<IslandBody*>& bodies, const std::vector<VecX>& dv,
                         VecX& scratch) {
  double sum = 0.0;
  for (size_t b = 0; b < bodies.size(); ++b) {
    bodies[b]->ApplySystemMatrix(dv[b], scratch);
    sum += dv[b].dot(scratch);
  }
  return sum;
}
}  // namespace

double CalcQpPgsTolerance(double h, bool warm_started, const SqpSettings& settings) {
  if (!warm_started) return settings.pgs.tolerance;
  // A sweep's w error e leaves a C error of h e (C = h w at the QP step). From the warm start the
  // SQP stops only with distance rows within f = warm_stop_distance_factor of their tolerance
  // (Iterate): keep h e to half of that, e <= f contact_tolerance / (2 h). At h = 1/60 s the
  // default 1e-4 1/s left 1.7e-6 m against the 1e-6 m asked, and each further SQP iteration
  // bought one PGS sweep.
  const double tight = 0.5 * settings.warm_stop_distance_factor * settings.contact_tolerance / h;
  return std::min(settings.pgs.tolerance, tight);
}

void SqpSolver::CalcPositions(double h, const std::vector<IslandBody*>& bodies,
                              const std::vector<VecX>& v) {
  for (size_t b = 0; b < bodies.size(); ++b) bodies[b]->CalcPositions(h, v[b], x_[b]);
}

void SqpSolver::BuildDelassus(const std::vector<IslandBody*>& bodies) {
  const int m = rows_.size();
  W_.setZero(m, m);
  // W_b = J_b A_b^-1 J_b^T per body, its columns kept across this step's SQP iterations where a
  // row's J is unchanged.
  columns_.Build(bodies, rows_);
  for (size_t b = 0; b < bodies.size(); ++b) {
    const std::vector<int>& rows = rows_.body_rows(static_cast<int>(b));
    const MatX& W_b = columns_.W(static_cast<int>(b));
    for (size_t i = 0; i < rows.size(); ++i)
      for (size_t k = 0; k < rows.size(); ++k) W_(rows[i], rows[k]) += W_b(i, k);
  }
  // Symmetrize (W is J A^-1 J^T; round-off makes it slightly asymmetric).
  W_ = 0.5 * (W_ + W_.transpose()).eval();
}

double SqpSolver::CalcViolationSum(double h, const std::vector<IslandBody*>& bodies,
                                   const std::vector<ConstraintSource*>& sources,
                                   const std::vector<VecX>& v) {
  CalcPositions(h, bodies, v);
  const IslandIterate iterate(h, bodies, v, x_);
  double sum = 0.0;
  for (ConstraintSource* source : sources) sum += source->CalcIslandViolationSum(iterate);
  return sum;
}

double SqpSolver::CalcMerit(double h, const std::vector<IslandBody*>& bodies,
                            const std::vector<ConstraintSource*>& sources,
                            const std::vector<VecX>& v, double rho) {
  for (size_t b = 0; b < bodies.size(); ++b) dv_[b] = v[b] - bodies[b]->v_star();
  return 0.5 * EnergyNormSquared(bodies, dv_, scratch_) +
         rho * CalcViolationSum(h, bodies, sources, v) / h;
}

KktResiduals SqpSolver::CalcFullStepCertificate(double h, const std::vector<IslandBody*>& bodies,
                                                const std::vector<ConstraintSource*>& sources,
                                                const SqpSettings& settings, StepStats& stats) {
  const double distance_scale = settings.CalcDistanceScale();
  if (!full_rows_at_v_qp_) {  // else the look-ahead pass collected them at this v_QP
    const auto t_rows = std::chrono::steady_clock::now();
    full_violation_ = full_rows_.Collect(h, bodies, sources, v_qp_, distance_scale);
    full_rows_at_v_qp_ = true;
    stats.ms_rows += MsSince(t_rows);
  }
  rows_.Store(lambda_qp_, qp_keyed_);
  full_rows_.WarmStart(qp_keyed_, full_lambda_);
  return CalcKktResiduals(bodies, full_rows_, full_lambda_, v_qp_, h, distance_scale, scratch_);
}

bool SqpSolver::HasTightDistanceRows(const KktResiduals& kkt, const SqpSettings& settings) {
  return kkt.max_distance_residual() <=
         settings.warm_stop_distance_factor * settings.violation_tolerance;
}

bool SqpSolver::IsCertifiedWithTightRows(const KktResiduals& full, const SqpSettings& settings) {
  return IsCertified(full, settings.violation_tolerance, settings.stationarity_tolerance) &&
         HasTightDistanceRows(full, settings);
}

bool SqpSolver::AcceptsFullStepResidual(const KktResiduals& full, const SqpSettings& settings,
                                        double residual, double violation) {
  // The l1 merit rejects full steps that the SQP needs near convergence (with Coulomb friction
  // the step need not lower the energy term; curved rows add second-order violation), and merit
  // steps of 1/2 converge only linearly. The certificate is the measure of progress here.
  const double bound =
      std::max(violation, settings.full_step_violation_factor * settings.violation_tolerance);
  return CalcCertificateResidual(full, settings.violation_tolerance,
                                 settings.stationarity_tolerance) <= 0.9 * residual &&
         full.max_primal() <= bound;
}

void SqpSolver::Solve(double h, const std::vector<DeformableBody*>& bodies,
                      const std::vector<ConstraintSource*>& sources, const SqpSettings& settings,
                      StepStats& stats) {
  std::vector<DeformableIslandBody> adapters;
  adapters.reserve(bodies.size());
  std::vector<IslandBody*> island;
  for (DeformableBody* body : bodies) island.push_back(&adapters.emplace_back(*body));
  Solve(h, island, sources, settings, stats);
}

void SqpSolver::Solve(double h, const std::vector<IslandBody*>& bodies,
                      const std::vector<ConstraintSource*>& sources, const SqpSettings& settings,
                      StepStats& stats) {
  columns_.Clear();  // this step's A (kept through a restart from v*: A is the same)
  BeginSolve(bodies, settings);
  warm_started_ = settings.warm_start && settings.warm_start_velocity &&
                  StartFromWarmMultipliers(h, bodies, sources, settings, stats);
  Iterate(h, bodies, sources, settings, stats);
  if (warm_started_ && !stats.converged && !stalled_infeasible_) {
    // Not certified from the warm-start velocity: the papers' start v* (docs/math.md §5.7). Not
    // after a stall where no push lowers the violation: measured, the start from v* stalled at
    // the same violation in every such step (the finger's 2 locked advances, 42 stress steps).
    const int iterations = stats.sqp_iterations;
    BeginSolve(bodies, settings);
    warm_started_ = false;
    Iterate(h, bodies, sources, settings, stats);
    stats.sqp_iterations += iterations;
  }
  for (size_t b = 0; b < bodies.size(); ++b) bodies[b]->set_v(v_k_[b]);
  rows_.Store(lambda_, previous_);
  stats.islands_dual++;
}

void SqpSolver::Iterate(double h, const std::vector<IslandBody*>& bodies,
                        const std::vector<ConstraintSource*>& sources, const SqpSettings& settings,
                        StepStats& stats) {
  const double distance_scale = settings.CalcDistanceScale();
  stats.sqp_iterations = 0;
  double rho = 0.0, last_alpha = 1.0;
  bool restoring = false;
  for (int k = 0;; ++k) {
    const double violation = CollectRowsAtIterate(h, bodies, sources, distance_scale, stats);
    if (k == 0) stats.violation_before = violation;
    stats.violation_after = violation;
    rows_.CountTypes(stats);
    rows_.WarmStart(iterate_, lambda_);
    if (rows_.empty()) {
      lambda_.resize(0);
      reported_.resize(0);
      // Without rows the minimizer is v*: a warm start inside every margin starts over there.
      if (k == 0 && warm_started_) stats.converged = false;
      break;  // nothing active: no LCP at all
    }
    // Certificate of the iterate (constraints/kkt_certificate.h).
    const KktResiduals kkt = CalcKktResidualsWithRefit(
        bodies, rows_, lambda_, v_k_, h, distance_scale, settings.violation_tolerance,
        settings.stationarity_tolerance, a_dv_, reported_);
    RecordKkt(kkt, stats);
    const double stationarity = kkt.stationarity;
    const bool force_free = lambda_.cwiseAbs().maxCoeff() == 0.0;
    // Converged: feasible to tolerance and stationary, or feasible with the line search stalled
    // (the QP direction no longer decreases the merit: more iterations would not move v), or
    // feasible again after restoration.
    const bool feasible = violation <= settings.violation_tolerance;
    stats.converged =
        IsCertified(kkt, settings.violation_tolerance, settings.stationarity_tolerance);
    // From the warm-start velocity: at least one QP (certified at the start itself, a contact
    // pushed in by less than its tolerance kept its old impulse), and distance rows within
    // warm_stop_distance_factor of their tolerance (certified at the tolerance's edge step after
    // step, a pressed contact sinks to the full tolerance; docs/math.md §5.7).
    const bool tight = !warm_started_ || (k > 0 && HasTightDistanceRows(kkt, settings));
    const bool done =
        tight && (settings.certificate_steps ? stats.converged
                                             : stationarity <= settings.stationarity_tolerance);
    if (feasible &&
        (restoring || done || (tight && force_free) || last_alpha < settings.stalled_step))
      break;
    if (k >= settings.max_iterations) {
      // SQP cap reached while infeasible: push-only restoration steps (docs/math.md §5.7,
      // "incremental dlambda >= 0": feasible in a few iterations, at the price of stationarity).
      if (feasible || k >= settings.max_iterations + settings.max_restoration_iterations) break;
      restoring = true;
    }
    const auto t_solve = std::chrono::steady_clock::now();
    metric_on_ = !restoring && settings.dual_curvature &&
                 metric_.Factor(h, bodies, sources, rows_, lambda_, v_k_);
    BuildQp(h, bodies, restoring);
    SolveQp(h, settings, stats);
    CalcQpVelocities(bodies, restoring);
    full_rows_at_v_qp_ = false;
    num_collected_ = rows_.size();
    look_ahead_keys_.clear();
    for (int pass = 0; !restoring && pass < settings.max_row_discovery_passes &&
                       AddRowsViolatedAtQpStep(h, bodies, sources, distance_scale, stats);
         ++pass) {
      BuildQp(h, bodies, restoring);
      SolveQp(h, settings, stats);
      CalcQpVelocities(bodies, restoring);
    }
    // No merit decrease along the QP step: the SQP cannot move v_k, so push-only restoration
    // takes over (docs/math.md §5.7); when no push lowers the violation either, nothing can.
    bool stuck = false;
    if (restoring) {
      stuck = !TakeRestorationStep(h, bodies, sources, settings, stats);
    } else {
      last_alpha = TakeMeritStep(h, bodies, sources, settings, kkt, rho, stats);
      restoring = last_alpha == 0.0;
    }
    rows_.Store(lambda_, iterate_);
    stats.sqp_iterations = k + 1;
    stats.ms_solve += MsSince(t_solve);
    if (stuck) {
      stalled_infeasible_ = true;
      break;
    }
  }
}

void SqpSolver::BeginSolve(const std::vector<IslandBody*>& bodies, const SqpSettings& settings) {
  const size_t nb = bodies.size();
  x_.resize(nb);
  v_k_.resize(nb);
  v_qp_.resize(nb);
  v_trial_.resize(nb);
  dv_.resize(nb);
  for (size_t b = 0; b < nb; ++b) v_k_[b] = bodies[b]->v();
  stalled_infeasible_ = false;
  if (settings.warm_start) {
    iterate_ = previous_;
  } else {
    iterate_.clear();
  }
  full_rows_at_v_k_ = full_rows_at_v_qp_ = false;
}

bool SqpSolver::StartFromWarmMultipliers(double h, const std::vector<IslandBody*>& bodies,
                                         const std::vector<ConstraintSource*>& sources,
                                         const SqpSettings& settings, StepStats& stats) {
  if (previous_.empty()) return false;
  const size_t nb = bodies.size();
  for (size_t b = 0; b < nb; ++b) v_trial_[b].setZero(v_k_[b].size());
  const auto t_rows = std::chrono::steady_clock::now();
  const double distance_scale = settings.CalcDistanceScale();
  full_rows_.Collect(h, bodies, sources, v_trial_, distance_scale);  // at x0 (v = 0)
  stats.ms_rows += MsSince(t_rows);
  full_rows_.WarmStart(previous_, full_lambda_);
  if (full_rows_.empty() || full_lambda_.cwiseAbs().maxCoeff() == 0.0) return false;
  // v = v* + A^-1 J_0^T lambda_0 (docs/math.md §5.7, warm-start velocity); a start only, so the
  // factor each body holds serves.
  full_rows_.AddImpulseVelocities(bodies, full_lambda_, dv_, v_k_);
  return true;
}

double SqpSolver::CollectRowsAtIterate(double h, const std::vector<IslandBody*>& bodies,
                                       const std::vector<ConstraintSource*>& sources,
                                       double distance_scale, StepStats& stats) {
  if (full_rows_at_v_k_) {
    // A full step moved v_k to v_QP exactly: its rows are already collected there.
    std::swap(rows_, full_rows_);
    full_rows_at_v_k_ = full_rows_at_v_qp_ = false;
    return full_violation_;
  }
  const auto t_rows = std::chrono::steady_clock::now();
  const double violation = rows_.Collect(h, bodies, sources, v_k_, distance_scale);
  stats.ms_rows += MsSince(t_rows);
  return violation;
}

void SqpSolver::BuildQp(double h, const std::vector<IslandBody*>& bodies, bool restoring) {
  // metric_on_ only outside restoration (Iterate).
  if (metric_on_) {
    metric_.CalcFreeVelocities(bodies, v_k_, v_free_);
    metric_.BuildW(bodies, rows_, W_);
  } else {
    BuildDelassus(bodies);
  }
  // q = C(x_k)/h + J_k (v_free - v_k), v_free = v* in the papers' metric A.
  const int m = rows_.size();
  q_.resize(m);
  for (int c = 0; c < m; ++c) {
    const ConstraintRow& row = rows_[c];
    double jdv = 0.0;
    row.ForEachEntry([&](int body, int block, const Vec3& J) {
      const VecX& v_free = metric_on_ ? v_free_[body] : bodies[body]->v_star();
      jdv += J.dot(v_free.segment<3>(3 * block) - v_k_[body].segment<3>(3 * block));
    });
    q_[c] = restoring ? row.C / h : row.C / h + jdv;
    // Friction rows: w_t = J_t v = J_t (v_free + Y lambda), so q = J_t v_free (restoration: 0).
    if (row.friction_of > 0) q_[c] = restoring ? 0.0 : jdv + rows_.CalcRowVelocity(c, v_k_);
  }
  rows_.CalcPgsRows(pgs_rows_);
  if (restoring) {
    lambda_qp_.setZero(m);
  } else {
    lambda_qp_ = lambda_;
  }
}

void SqpSolver::SolveQp(double h, const SqpSettings& settings, StepStats& stats) {
  PgsSettings pgs_settings = settings.pgs;
  pgs_settings.tolerance = CalcQpPgsTolerance(h, warm_started_, settings);
  pgs_settings.validate_input = false;  // rows built here: W symmetric by construction
  pgs_settings.w_workspace = &w_;
  const PgsStats pgs = SolvePgs(W_, q_, pgs_rows_, lambda_qp_, pgs_settings);
  stats.pgs_sweeps += pgs.sweeps;
  stats.lcp_residual = pgs.residual;
  if (settings.polish_active_set && pgs.residual > settings.polish.tolerance) {
    stats.active_set_solves++;
    stats.lcp_residual = PolishActiveSet(W_, q_, pgs_rows_, lambda_qp_, settings.pgs,
                                         settings.polish, &stats.pgs_sweeps);
  }
}

// v_QP = v* + A^-1 J^T lambda_QP (restoration: v_k + A^-1 J^T dlambda; curved metric:
// v_free + N^-1 J^T lambda_QP).
void SqpSolver::CalcQpVelocities(const std::vector<IslandBody*>& bodies, bool restoring) {
  if (metric_on_) {
    v_qp_ = v_free_;
    metric_.AddImpulseVelocities(rows_, lambda_qp_, v_qp_);
    return;
  }
  for (size_t b = 0; b < bodies.size(); ++b) {
    v_qp_[b] = restoring ? v_k_[b] : bodies[b]->v_star();
    columns_.AddImpulseVelocity(static_cast<int>(b), *bodies[b],
                                rows_.body_rows(static_cast<int>(b)), lambda_qp_, v_qp_[b]);
  }
}

bool SqpSolver::AddRowsViolatedAtQpStep(double h, const std::vector<IslandBody*>& bodies,
                                        const std::vector<ConstraintSource*>& sources,
                                        double distance_scale, StepStats& stats) {
  const auto t_rows = std::chrono::steady_clock::now();
  full_violation_ = full_rows_.Collect(h, bodies, sources, v_qp_, distance_scale);
  full_rows_at_v_qp_ = true;
  rows_.SetLookAheadRows(full_rows_, num_collected_, look_ahead_keys_, h, v_k_, v_qp_);
  stats.ms_rows += MsSince(t_rows);
  // Done when the look-ahead rows are the ones the QP had (now relinearized at this v_QP).
  next_look_ahead_keys_.clear();
  for (int c = num_collected_; c < rows_.size(); ++c) next_look_ahead_keys_.push_back(rows_[c].key);
  std::sort(next_look_ahead_keys_.begin(), next_look_ahead_keys_.end());
  if (next_look_ahead_keys_ == look_ahead_keys_) return false;
  for (const std::uint64_t key : next_look_ahead_keys_)
    if (!std::binary_search(look_ahead_keys_.begin(), look_ahead_keys_.end(), key))
      ++stats.rows_discovered;
  std::swap(look_ahead_keys_, next_look_ahead_keys_);
  full_rows_at_v_qp_ = false;  // the QP is solved again: a new v_QP
  // Look-ahead rows start from 0 (the collected keep lambda_k).
  lambda_.conservativeResize(rows_.size());
  lambda_.tail(rows_.size() - num_collected_).setZero();
  return true;
}

// Accepts the push only as far as it lowers the total violation (halving, as the merit).
bool SqpSolver::TakeRestorationStep(double h, const std::vector<IslandBody*>& bodies,
                                    const std::vector<ConstraintSource*>& sources,
                                    const SqpSettings& settings, StepStats& stats) {
  const size_t nb = bodies.size();
  const double before = CalcViolationSum(h, bodies, sources, v_k_);
  double alpha = 1.0;
  bool lowered = false;
  for (int halving = 0; halving <= settings.max_line_search_halvings && !lowered; ++halving) {
    if (halving > 0) alpha *= 0.5;
    for (size_t b = 0; b < nb; ++b) v_trial_[b] = v_k_[b] + alpha * (v_qp_[b] - v_k_[b]);
    lowered = CalcViolationSum(h, bodies, sources, v_trial_) < before;
  }
  stats.restoration_iterations++;
  if (!lowered) return false;  // no push lowers the violation: v_k stays
  for (size_t b = 0; b < nb; ++b) v_k_[b] += alpha * (v_qp_[b] - v_k_[b]);
  lambda_ += alpha * lambda_qp_;
  return true;
}

// Merit backtracking from (v_k, lambda_k) towards (v_QP, lambda_QP), or the full step taken on its
// own certificate. Returns the step length.
double SqpSolver::TakeMeritStep(double h, const std::vector<IslandBody*>& bodies,
                                const std::vector<ConstraintSource*>& sources,
                                const SqpSettings& settings, const KktResiduals& kkt, double& rho,
                                StepStats& stats) {
  const size_t nb = bodies.size();
  rho = std::max(rho, 2.0 * lambda_qp_.cwiseAbs().maxCoeff());
  // The full step's certificate first. Certified with its distance rows tight, the full step is
  // the iterate the SQP stops at next, and the merit search would take it either way (a
  // decrease at alpha = 1, or else as a certificate step): taken without the merit's two
  // violation sums over every limited element. From a warm start already at the answer the QP
  // step is ~0 and the merit's decrease fails on round-off (the finger's held presses).
  KktResiduals full;
  if (settings.certificate_steps) {
    full = CalcFullStepCertificate(h, bodies, sources, settings, stats);
    if (IsCertifiedWithTightRows(full, settings)) {
      TakeFullStep();
      return 1.0;
    }
  }
  const double phi_k = CalcMerit(h, bodies, sources, v_k_, rho);
  for (size_t b = 0; b < nb; ++b) dv_[b] = v_qp_[b] - v_k_[b];
  const double step_norm = EnergyNormSquared(bodies, dv_, scratch_);
  double alpha = 1.0;
  const double residual_k =
      CalcCertificateResidual(kkt, settings.violation_tolerance, settings.stationarity_tolerance);
  bool certificate_step = false, decreased = false;
  for (int halving = 0; halving <= settings.max_line_search_halvings; ++halving) {
    if (halving > 0) alpha *= 0.5;
    for (size_t b = 0; b < nb; ++b) v_trial_[b] = v_k_[b] + alpha * (v_qp_[b] - v_k_[b]);
    decreased = CalcMerit(h, bodies, sources, v_trial_, rho) <= phi_k - 1e-4 * alpha * step_norm;
    if (decreased) break;
    certificate_step = halving == 0 && settings.certificate_steps &&
                       AcceptsFullStepResidual(full, settings, residual_k, kkt.max_primal());
    if (certificate_step) break;
  }
  if (!decreased && !certificate_step) return 0.0;  // no trial lowers the merit: v_k stays
  if (certificate_step) {
    TakeFullStep();
  } else {
    for (size_t b = 0; b < nb; ++b) v_k_[b] += alpha * (v_qp_[b] - v_k_[b]);
    lambda_ += alpha * (lambda_qp_ - lambda_);
    // A full step lands on v_QP (to rounding): the rows collected there serve the next iteration.
    full_rows_at_v_k_ = alpha == 1.0 && full_rows_at_v_qp_;
  }
  return alpha;
}

void SqpSolver::TakeFullStep() {
  // (v_QP, lambda_QP) exactly, so the next iteration takes the rows just collected there.
  v_k_ = v_qp_;
  lambda_ = lambda_qp_;
  full_rows_at_v_k_ = true;
}

}  // namespace taut
