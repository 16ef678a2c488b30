#include "constraints/sqp_solver.h"

#include "constraints/active_set_polish.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

namespace taut {

namespace {
double MsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// ||dv||_A^2 = dv^T A dv summed over bodies (dv read on free DOFs).
double EnergyNormSquared(const std::vector<DeformableBody*>& bodies, const std::vector<VecX>& dv,
                         VecX& scratch) {
  double sum = 0.0;
  for (size_t b = 0; b < bodies.size(); ++b) {
    bodies[b]->ApplySystemMatrix(dv[b], scratch);
    sum += dv[b].dot(scratch);
  }
  return sum;
}
}  // namespace

double SqpSolver::CollectRows(double h, const std::vector<DeformableBody*>& bodies,
                              const std::vector<ConstraintSource*>& sources) {
  rows_.clear();
  for (ConstraintSource* source : sources) {
    const auto it = std::find(bodies.begin(), bodies.end(), &source->body());
    const int b = static_cast<int>(it - bodies.begin());
    // x_k = x0 + h v_k of that body.
    v_trial_[b] = bodies[b]->x0() + h * v_k_[b];
    source->AppendRows(v_trial_[b], b, rows_);
  }
  double violation = 0.0;
  for (const ConstraintRow& row : rows_) violation = std::max(violation, -row.C);
  body_rows_.assign(bodies.size(), {});
  for (size_t c = 0; c < rows_.size(); ++c) body_rows_[rows_[c].body].push_back(static_cast<int>(c));
  return violation;
}

void SqpSolver::BuildDelassus(const std::vector<DeformableBody*>& bodies) {
  const int m = static_cast<int>(rows_.size());
  W_.setZero(m, m);
  Y_.resize(bodies.size());
  for (size_t b = 0; b < bodies.size(); ++b) {
    const std::vector<int>& rows = body_rows_[b];
    if (rows.empty()) continue;
    // Y_b = A^-1 J_b^T: scatter J rows into columns, then one multi-column solve.
    MatX& Y = Y_[b];
    Y.setZero(3 * bodies[b]->num_nodes(), static_cast<int>(rows.size()));
    for (size_t k = 0; k < rows.size(); ++k) {
      const ConstraintRow& row = rows_[rows[k]];
      for (int n = 0; n < row.num_nodes; ++n) Y.col(k).segment<3>(3 * row.nodes[n]) += row.J[n];
    }
    bodies[b]->SolveSystemColumns(Y);
    // W_c. = J_c Y (J sparse over a row's nodes): a 1x3 times 3xm product per node.
    for (size_t i = 0; i < rows.size(); ++i) {
      const ConstraintRow& row = rows_[rows[i]];
      w_row_.setZero(static_cast<int>(rows.size()));
      for (int n = 0; n < row.num_nodes; ++n)
        w_row_.noalias() += row.J[n].transpose() * Y.middleRows<3>(3 * row.nodes[n]);
      for (size_t k = 0; k < rows.size(); ++k) W_(rows[i], rows[k]) = w_row_[k];
    }
  }
  // Symmetrize (W is J A^-1 J^T; round-off makes it slightly asymmetric).
  W_ = 0.5 * (W_ + W_.transpose()).eval();
}

double SqpSolver::CalcViolationSum(double h, const std::vector<DeformableBody*>& bodies,
                                   const std::vector<ConstraintSource*>& sources,
                                   const std::vector<VecX>& v) {
  double sum = 0.0;
  for (ConstraintSource* source : sources) {
    const int b = static_cast<int>(std::find(bodies.begin(), bodies.end(), &source->body()) -
                                   bodies.begin());
    sum += source->CalcViolationSum(bodies[b]->x0() + h * v[b]);
  }
  return sum;
}

double SqpSolver::CalcMerit(double h, const std::vector<DeformableBody*>& bodies,
                            const std::vector<ConstraintSource*>& sources,
                            const std::vector<VecX>& v, double rho) {
  for (size_t b = 0; b < bodies.size(); ++b) dv_[b] = v[b] - bodies[b]->v_star();
  return 0.5 * EnergyNormSquared(bodies, dv_, scratch_) +
         rho * CalcViolationSum(h, bodies, sources, v) / h;
}

double SqpSolver::CalcRowVelocity(const ConstraintRow& row, const std::vector<VecX>& v) const {
  double jv = 0.0;
  for (int n = 0; n < row.num_nodes; ++n) jv += row.J[n].dot(v[row.body].segment<3>(3 * row.nodes[n]));
  return jv;
}

void SqpSolver::BuildPgsRows() {
  // Unilateral rows, and friction pairs on the Coulomb disk of their contact's normal row.
  pgs_rows_.assign(rows_.size(), MakeUnilateralRow());
  for (size_t c = 0; c < rows_.size(); ++c) {
    const ConstraintRow& row = rows_[c];
    if (row.friction_of == 0) continue;
    PgsRow& p = pgs_rows_[c];
    p.kind = RowKind::kFriction;
    p.cone = FrictionCone::kDisk;
    p.normal = static_cast<int>(c) - row.friction_of;
    p.partner = row.friction_of == 1 ? static_cast<int>(c) + 1 : static_cast<int>(c) - 1;
    p.lo = -std::numeric_limits<double>::infinity();
    p.mu = row.mu;
  }
}

void SqpSolver::WarmStart(const std::vector<std::pair<std::uint64_t, double>>& from) {
  lambda_.setZero(static_cast<int>(rows_.size()));
  for (size_t c = 0; c < rows_.size(); ++c) {
    const auto it = std::lower_bound(from.begin(), from.end(),
                                     std::make_pair(rows_[c].key, -HUGE_VAL));
    if (it != from.end() && it->first == rows_[c].key) lambda_[c] = it->second;
  }
}

void SqpSolver::StoreMultipliers(std::vector<std::pair<std::uint64_t, double>>& to) const {
  to.clear();
  for (size_t c = 0; c < rows_.size(); ++c)
    if (lambda_[c] != 0.0) to.emplace_back(rows_[c].key, lambda_[c]);
  std::sort(to.begin(), to.end());
}

void SqpSolver::Solve(double h, const std::vector<DeformableBody*>& bodies,
                      const std::vector<ConstraintSource*>& sources, const SqpSettings& settings,
                      StepStats& stats) {
  const size_t nb = bodies.size();
  v_k_.resize(nb);
  v_qp_.resize(nb);
  v_trial_.resize(nb);
  dv_.resize(nb);
  for (size_t b = 0; b < nb; ++b) v_k_[b] = bodies[b]->v();
  if (settings.warm_start) {
    iterate_ = previous_;
  } else {
    iterate_.clear();
  }
  double rho = 0.0, last_alpha = 1.0;
  bool restoring = false;
  for (int k = 0;; ++k) {
    auto t_rows = std::chrono::steady_clock::now();
    const double violation = CollectRows(h, bodies, sources);
    stats.ms_rows += MsSince(t_rows);
    if (k == 0) stats.violation_before = violation;
    stats.violation_after = violation;
    stats.rows_strain = static_cast<int>(std::count_if(
        rows_.begin(), rows_.end(), [](const auto& r) { return r.type == RowType::kStrainLimit; }));
    stats.rows_energy = static_cast<int>(std::count_if(
        rows_.begin(), rows_.end(), [](const auto& r) { return r.type == RowType::kEnergyLimit; }));
    stats.rows_contact = static_cast<int>(std::count_if(
        rows_.begin(), rows_.end(), [](const auto& r) { return r.type == RowType::kContact; }));
    WarmStart(iterate_);
    if (rows_.empty()) {
      lambda_.resize(0);
      break;  // nothing active: no LCP at all
    }
    // Stationarity of the iterate: ||A(v_k - v*) - J_k^T lambda_k|| / ||J_k^T lambda_k||.
    double residual = 0.0, force = 0.0;
    for (size_t b = 0; b < nb; ++b) {
      dv_[b] = v_k_[b] - bodies[b]->v_star();
      bodies[b]->ApplySystemMatrix(dv_[b], scratch_);
      VecX& jt = jt_;
      jt.setZero(scratch_.size());
      for (int c : body_rows_[b])
        for (int n = 0; n < rows_[c].num_nodes; ++n)
          jt.segment<3>(3 * rows_[c].nodes[n]) += lambda_[c] * rows_[c].J[n];
      // Constrained DOFs carry reaction forces: compare on free DOFs only (A v is 0 there).
      for (int i = 0; i < bodies[b]->num_nodes(); ++i)
        if (bodies[b]->node_kind(i) != NodeKind::kFree) jt.segment<3>(3 * i).setZero();
      residual += (scratch_ - jt).squaredNorm();
      force += jt.squaredNorm();
    }
    const double stationarity = force > 0.0 ? std::sqrt(residual / force) : std::sqrt(residual);
    stats.stationarity = stationarity;
    // Converged: feasible to tolerance and stationary, or feasible with the line search stalled
    // (the QP direction no longer decreases the merit: more iterations would not move v), or
    // feasible again after restoration.
    const bool feasible = violation <= settings.violation_tolerance;
    if (feasible && (restoring || stationarity <= settings.stationarity_tolerance ||
                     force == 0.0 || last_alpha < settings.stalled_step)) {
      break;
    }
    if (k >= settings.max_iterations) {
      // SQP cap reached while infeasible: push-only restoration steps (MATH.md §5 "incremental
      // dlambda >= 0": feasible in a few iterations, at the price of stationarity).
      if (feasible || k >= settings.max_iterations + settings.max_restoration_iterations) {
        stats.converged = feasible;
        break;
      }
      restoring = true;
    }
    const auto t_solve = std::chrono::steady_clock::now();
    BuildDelassus(bodies);
    // q = C(x_k)/h + J_k (v* - v_k).
    const int m = static_cast<int>(rows_.size());
    q_.resize(m);
    for (int c = 0; c < m; ++c) {
      const ConstraintRow& row = rows_[c];
      double jdv = 0.0;
      for (int n = 0; n < row.num_nodes; ++n)
        jdv += row.J[n].dot(bodies[row.body]->v_star().segment<3>(3 * row.nodes[n]) -
                            v_k_[row.body].segment<3>(3 * row.nodes[n]));
      q_[c] = restoring ? row.C / h : row.C / h + jdv;
      // Friction rows: w_t = J_t v = J_t (v* + Y lambda), so q = J_t v* (restoration: 0).
      if (row.friction_of > 0) q_[c] = restoring ? 0.0 : jdv + CalcRowVelocity(row, v_k_);
    }
    BuildPgsRows();
    if (restoring) {
      lambda_qp_.setZero(m);
    } else {
      lambda_qp_ = lambda_;
    }
    PgsSettings pgs_settings = settings.pgs;
    pgs_settings.validate_input = false;  // rows built here: W symmetric by construction
    pgs_settings.w_workspace = &w_;
    const PgsStats pgs = SolvePgs(W_, q_, pgs_rows_, lambda_qp_, pgs_settings);
    stats.pgs_sweeps += pgs.sweeps;
    if (settings.polish_active_set && pgs.residual > settings.polish.tolerance) {
      stats.active_set_solves++;
      PolishActiveSet(W_, q_, pgs_rows_, lambda_qp_, settings.pgs, settings.polish,
                      &stats.pgs_sweeps);
    }
    // v_QP = v* + Y lambda_QP (restoration: v_k + Y dlambda).
    for (size_t b = 0; b < nb; ++b) {
      v_qp_[b] = restoring ? v_k_[b] : bodies[b]->v_star();
      const std::vector<int>& rows = body_rows_[b];
      for (size_t i = 0; i < rows.size(); ++i) v_qp_[b] += Y_[b].col(i) * lambda_qp_[rows[i]];
    }
    if (restoring) {
      // Accept the push only as far as it lowers the total violation (halving, as the merit).
      const double before = CalcViolationSum(h, bodies, sources, v_k_);
      double alpha = 1.0;
      for (int halving = 0; halving < settings.max_line_search_halvings; ++halving) {
        for (size_t b = 0; b < nb; ++b) v_trial_[b] = v_k_[b] + alpha * (v_qp_[b] - v_k_[b]);
        if (CalcViolationSum(h, bodies, sources, v_trial_) < before) break;
        alpha *= 0.5;
      }
      for (size_t b = 0; b < nb; ++b) v_k_[b] += alpha * (v_qp_[b] - v_k_[b]);
      lambda_ += alpha * lambda_qp_;
      StoreMultipliers(iterate_);
      stats.restoration_iterations++;
      stats.sqp_iterations = k + 1;
      stats.ms_solve += MsSince(t_solve);
      continue;
    }
    // Merit backtracking.
    rho = std::max(rho, 2.0 * lambda_qp_.maxCoeff());
    const double phi_k = CalcMerit(h, bodies, sources, v_k_, rho);
    for (size_t b = 0; b < nb; ++b) dv_[b] = v_qp_[b] - v_k_[b];
    const double step_norm = EnergyNormSquared(bodies, dv_, scratch_);
    double alpha = 1.0;
    for (int halving = 0; halving < settings.max_line_search_halvings; ++halving) {
      for (size_t b = 0; b < nb; ++b) v_trial_[b] = v_k_[b] + alpha * (v_qp_[b] - v_k_[b]);
      if (CalcMerit(h, bodies, sources, v_trial_, rho) <= phi_k - 1e-4 * alpha * step_norm) break;
      alpha *= 0.5;
    }
    for (size_t b = 0; b < nb; ++b) v_k_[b] += alpha * (v_qp_[b] - v_k_[b]);
    lambda_ += alpha * (lambda_qp_ - lambda_);
    last_alpha = alpha;
    StoreMultipliers(iterate_);
    stats.sqp_iterations = k + 1;
    stats.ms_solve += MsSince(t_solve);
  }
  for (size_t b = 0; b < nb; ++b) bodies[b]->mutable_v() = v_k_[b];
  StoreMultipliers(previous_);
}

}  // namespace taut
