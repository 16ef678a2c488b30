#include "constraints/primal_solver.h"

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

double Dot(const std::vector<VecX>& a, const std::vector<VecX>& b) {
  double sum = 0.0;
  for (size_t i = 0; i < a.size(); ++i) sum += a[i].dot(b[i]);
  return sum;
}

// Projection of y onto the disk |y| <= r and its Jacobian D = dProj/dy:
// inside I; outside (r/|y|)(I - y y^T/|y|^2) (docs/math.md §5.8, Coulomb disk).
Eigen::Vector2d ProjectOnDisk(const Eigen::Vector2d& y, double r, Eigen::Matrix2d* D) {
  const double norm = y.norm();
  if (norm <= r) {
    if (D) D->setIdentity();
    return y;
  }
  if (norm == 0.0 || r <= 0.0) {
    if (D) D->setZero();
    return Eigen::Vector2d::Zero();
  }
  const Eigen::Vector2d unit = y / norm;
  if (D) *D = (r / norm) * (Eigen::Matrix2d::Identity() - unit * unit.transpose());
  return r * unit;
}

// Projection of a scalar multiplier onto its interval [lo, hi] (unilateral: [0, inf)).
double ProjectOnInterval(double y, double lo, double hi, double* D) {
  if (y <= lo) {
    if (D) *D = 0.0;
    return lo;
  }
  if (y >= hi) {
    if (D) *D = 0.0;
    return hi;
  }
  if (D) *D = 1.0;
  return y;
}

bool AreSameVelocities(const std::vector<VecX>& a, const std::vector<VecX>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (a[i].size() != b[i].size() || a[i] != b[i]) return false;
  return true;
}

double LowerBound(const ConstraintRow& row) { return row.bilateral ? row.lo : 0.0; }
double UpperBound(const ConstraintRow& row) {
  return row.bilateral ? row.hi : std::numeric_limits<double>::infinity();
}
}  // namespace

void PrimalSolver::CalcPenalties(double h, const std::vector<IslandBody*>& bodies,
                                 const PrimalSettings& settings) {
  const int m = rows_.size();
  rho_.setZero(m);
  for (int c = 0; c < m; ++c) {
    const ConstraintRow& row = rows_[c];
    if (row.friction_of > 0) {
      rho_[c] = rho_[c - row.friction_of];
      continue;
    }
    // w_c = sum_i J_ci^T M_i^-1 J_ci: the diagonal of W with A replaced by its mass part.
    double w = 0.0, jj = 0.0;
    row.ForEachEntry([&](int body, int block, const Vec3& J) {
      w += bodies[body]->CalcBlockMobility(block, J);
      jj += J.squaredNorm();
    });
    if (!(w > 0.0)) {
      rho_[c] = 0.0;
      continue;
    }
    // A pushing row's curvature G_c = h lambda_bar_c (-d^2C/dx^2) stiffens the Newton matrix
    // along J: with mass |J|^2 / w and stiffness J^T G_c J / |J|^2 along J/|J|, the effective
    // mobility is 1 / w_eff = 1 / w + h lambda_bar_c J^T (-d^2C) J / |J|^4. Without it, rho of
    // a tiny energy limit (large lambda, curvature K_e / U_max) was far below the multiplier
    // iteration's need: 40 iterations each cutting the violation only by 0.9 (docs/math.md §5.8,
    // curvature in the effective mass).
    rho_[c] = settings.penalty_scale / w;
    if (row.curvature_along_j > 0.0 && c < lambda_bar_.size() && lambda_bar_[c] > 0.0)
      rho_[c] += settings.penalty_scale * h * lambda_bar_[c] * row.curvature_along_j / (jj * jj);
  }
  // Within a multiplier iteration limit rows keep the rho they started it with: rho from a trial
  // point's J would make Phi's slope along d disagree with grad Phi . d.
  fresh_rho_ = rho_;
  if (rho_kept_) rows_.OverwriteByKey(kept_rho_, rho_);
}

void PrimalSolver::GrowStalledPenalties(const PrimalSettings& settings, double tolerance,
                                        int iteration) {
  // A limit row still violated by more than the tolerance whose violation fell by less than half
  // over the last multiplier iteration has its rho multiplied by penalty_growth, up to
  // max_penalty_growth times its Delassus value (docs/math.md §5.8, penalty growth). Once the
  // iterate is feasible, a row with full curvature that pushes (lambda_bar > 0) while slack by
  // more than the tolerance counts its complementarity residual C the same way: its multiplier
  // falls by only rho C / h per iteration. rho_ holds the kept, already grown, penalties of the
  // last multiplier iteration.
  const bool count_slack_push = settings.grow_on_slack_push && violation_ <= tolerance;
  const double cap = iteration >= settings.late_growth_iteration
                         ? std::max(settings.max_penalty_growth, settings.late_max_penalty_growth)
                         : settings.max_penalty_growth;
  const int m = rows_.size();
  last_.setConstant(m, -1.0);
  growth_.setOnes(m);
  rows_.OverwriteByKey(last_violation_, last_);
  rows_.OverwriteByKey(kept_growth_, growth_);
  last_violation_.clear();
  kept_growth_.clear();
  for (int c = 0; c < m; ++c) {
    if (!IsLimitRow(rows_[c])) continue;
    const bool pushing_while_slack =
        count_slack_push && rows_[c].full_curvature && lambda_bar_[c] > 0.0 && rows_[c].C > 0.0;
    const double violation = pushing_while_slack ? rows_[c].C : std::max(0.0, -rows_[c].C);
    if (violation > tolerance && last_[c] >= 0.0 && violation > 0.5 * last_[c]) {
      const double next = std::min(growth_[c] * settings.penalty_growth, cap);
      rho_[c] *= next / growth_[c];
      growth_[c] = next;
    }
    last_violation_.emplace_back(rows_[c].key, violation);
    if (growth_[c] != 1.0) kept_growth_.emplace_back(rows_[c].key, growth_[c]);
  }
  std::sort(last_violation_.begin(), last_violation_.end());
  std::sort(kept_growth_.begin(), kept_growth_.end());
}

bool PrimalSolver::CapKeptPenalties(const PrimalSettings& settings) {
  const double cap = std::max(settings.max_penalty_growth, settings.late_max_penalty_growth);
  bool lowered = false;
  for (int c = 0; c < rows_.size(); ++c) {
    const double bound = cap * fresh_rho_[c];
    if (rho_[c] > bound) {
      rho_[c] = bound;
      lowered = true;
    }
  }
  if (lowered) KeepPenalties();
  return lowered;
}

void PrimalSolver::KeepPenalties() {
  // Limit rows only: kept contact penalties left a rigid stack's friction unconverged (95 of 480
  // steps against 4; docs/math.md §5.8).
  kept_rho_.clear();
  for (int c = 0; c < rows_.size(); ++c)
    if (IsLimitRow(rows_[c])) kept_rho_.emplace_back(rows_[c].key, rho_[c]);
  std::sort(kept_rho_.begin(), kept_rho_.end());
  rho_kept_ = true;
}

void PrimalSolver::LinearizeRows(double h, const std::vector<IslandBody*>& bodies) {
  const int m = rows_.size();
  g0_.resize(m);
  in_pattern_.assign(m, 1);
  coupled_ = false;
  for (int c = 0; c < m; ++c) {
    const ConstraintRow& row = rows_[c];
    // g_c(v_ + dv) = C_c/h + J_c dv = g0_c + J_c (v_ + dv); friction rows target J_t v = 0.
    g0_[c] = row.friction_of > 0 ? 0.0 : row.C / h - rows_.CalcRowVelocity(c, v_);
    // Rows of one element are adjacent and share its nodes: the previous row's answer holds.
    const ConstraintRow* previous = c > 0 ? &rows_[c - 1] : nullptr;
    const bool same_nodes = previous && previous->body == row.body &&
                            previous->body2 == row.body2 && previous->num_nodes == row.num_nodes &&
                            previous->num_nodes2 == row.num_nodes2 &&
                            previous->nodes == row.nodes && previous->nodes2 == row.nodes2;
    if (row.element >= 0 && row.body2 < 0) {
      // An element's rows: its node blocks are in the pattern by construction.
    } else if (same_nodes) {
      in_pattern_[c] = in_pattern_[c - 1];
    } else {
      row.ForEachEntry([&](int body_a, int a, const Vec3&) {
        row.ForEachEntry([&](int body_b, int b, const Vec3&) {
          if (body_a == body_b && !bodies[body_a]->IsInNewtonPattern(a, b)) in_pattern_[c] = 0;
        });
      });
    }
    const bool two_sided = row.body2 >= 0 && row.body2 != row.body;
    if (two_sided || !in_pattern_[c]) coupled_ = true;
  }
  // A friction pair is held on the pattern only as a whole (its D couples the two rows).
  for (int c = 0; c < m; ++c)
    if (rows_[c].friction_of == 1)
      in_pattern_[c] = in_pattern_[c + 1] = in_pattern_[c] && in_pattern_[c + 1];
}

void PrimalSolver::CollectCurvature(double h, const std::vector<IslandBody*>& bodies,
                                    const std::vector<ConstraintSource*>& sources) {
  curvature_.CollectLimitRows(h, bodies, sources, rows_, lambda_, v_);
}

void PrimalSolver::CalcProjectedMultipliers() {
  const int m = rows_.size();
  lambda_.resize(m);
  d_unit_.resize(m);
  d_disk_.resize(m);
  for (int c = 0; c < m; ++c) jv_[c] = rows_.CalcRowVelocity(c, v_);
  for (int c = 0; c < m; ++c) {
    const ConstraintRow& row = rows_[c];
    if (row.friction_of == 2) continue;  // done with its pair
    if (row.friction_of == 1) {
      // y_t = lambda_bar_t - rho J_t v on the disk of radius mu lambda_bar_n.
      const double radius = row.mu * std::max(0.0, lambda_bar_[c - 1]);
      const Eigen::Vector2d y(lambda_bar_[c] - rho_[c] * jv_[c],
                              lambda_bar_[c + 1] - rho_[c] * jv_[c + 1]);
      const Eigen::Vector2d t = ProjectOnDisk(y, radius, &d_disk_[c]);
      lambda_[c] = t[0];
      lambda_[c + 1] = t[1];
      continue;
    }
    const double y = lambda_bar_[c] - rho_[c] * (g0_[c] + jv_[c]);
    lambda_[c] = ProjectOnInterval(y, LowerBound(row), UpperBound(row), &d_unit_[c]);
  }
}

void PrimalSolver::CalcGradient(const std::vector<IslandBody*>& bodies) {
  // A (v - v*) is the certificate's product when it was taken at this v (the same bits).
  const size_t nb = bodies.size();
  const bool certified_here = AreSameVelocities(a_dv_v_, v_);
  for (size_t b = 0; b < nb; ++b) {
    w_[b] = v_[b] - bodies[b]->v_star();
    if (certified_here)
      aw_[b] = a_dv_[b];
    else
      bodies[b]->ApplySystemMatrix(w_[b], aw_[b]);
    grad_[b] = aw_[b];
  }
  for (int c = 0; c < rows_.size(); ++c) {
    if (lambda_[c] == 0.0) continue;
    rows_[c].ForEachEntry([&](int body, int block, const Vec3& J) {
      grad_[body].segment<3>(3 * block) -= lambda_[c] * J;
    });
  }
  for (size_t b = 0; b < nb; ++b)
    for (int i = 0; i < bodies[b]->num_blocks(); ++i)
      if (!bodies[b]->is_free_block(i)) grad_[b].segment<3>(3 * i).setZero();
}

void PrimalSolver::AddRowProduct(const std::vector<IslandBody*>& bodies, int p, int q,
                                 double scale) {
  rows_[p].ForEachEntry([&](int body_a, int a, const Vec3& Ja) {
    rows_[q].ForEachEntry([&](int body_b, int b, const Vec3& Jb) {
      if (body_a == body_b) bodies[body_a]->AddNewtonBlock(a, b, scale * Ja * Jb.transpose());
    });
  });
}

void PrimalSolver::ChooseFactorReuse(const std::vector<IslandBody*>& bodies,
                                     const PrimalSettings& settings) {
  // A body keeps its last factor when factoring costs at least min_refactor_cost CG iterations,
  // unless the last solve with a kept factor needed more than half the cheapest such cost.
  any_stale_ = false;
  stale_budget_ = std::numeric_limits<double>::infinity();
  stale_.assign(bodies.size(), 0);
  for (size_t b = 0; b < bodies.size(); ++b) {
    const double cost = settings.reuse_factorization ? bodies[b]->CalcNewtonRefactorCost() : 0.0;
    if (refactor_next_ || cost <= 0.0 || cost < settings.min_refactor_cost) continue;
    stale_[b] = 1;
    any_stale_ = true;
    stale_budget_ = std::min(stale_budget_, 0.5 * cost);
  }
  refactor_next_ = false;
}

int PrimalSolver::AssembleNewtonMatrices(const std::vector<IslandBody*>& bodies,
                                         bool clamp_on_failure) {
  // Bodies that keep their factor need no new H: their step is CG on the exact operator.
  if (std::all_of(stale_.begin(), stale_.end(), [](char s) { return s != 0; })) return 0;
  for (IslandBody* body : bodies) body->ResetNewtonMatrix();
  curvature_.AddToNewtonMatrices(bodies);
  // Rows of one element are adjacent and share its nodes: their rho J^T J are summed into one
  // dense element block first and scattered once (group_ below).
  group_.Clear();
  for (int c = 0; c < rows_.size(); ++c) {
    const ConstraintRow& row = rows_[c];
    if (!in_pattern_[c] || row.friction_of == 2) continue;
    if (row.friction_of == 1) {
      // rho [J_1; J_2]^T D [J_1; J_2].
      const Eigen::Matrix2d& D = d_disk_[c];
      for (int p = 0; p < 2; ++p)
        for (int q = 0; q < 2; ++q)
          if (D(p, q) != 0.0) AddRowProduct(bodies, c + p, c + q, rho_[c] * D(p, q));
      continue;
    }
    if (d_unit_[c] == 0.0) continue;
    if (row.body2 >= 0 && row.body2 != row.body) {
      AddRowProduct(bodies, c, c, rho_[c] * d_unit_[c]);
      continue;
    }
    if (!group_.Matches(row)) {
      group_.Scatter(bodies);
      group_.Start(row);
    }
    group_.Add(row, rho_[c] * d_unit_[c]);
  }
  group_.Scatter(bodies);
  int factored = 0;
  try {
    for (size_t b = 0; b < bodies.size(); ++b) {
      if (stale_[b]) continue;
      bodies[b]->FactorNewtonMatrix();
      ++factored;
    }
  } catch (const SimulationError&) {
    // The curvature is only a metric: without it H = A + sum rho J^T D J is positive definite.
    if (curvature_.empty()) throw;
    // Its element blocks may keep mildly negative modes (strain_frame_curvature.h): clamped
    // exactly, G usually lets H factor, and the step keeps the curvature (docs/math.md §5.9).
    if (!clamp_on_failure || curvature_.ClampIndefiniteElementBlocks() == 0) curvature_.Clear();
    return factored + AssembleNewtonMatrices(bodies, false);
  }
  return factored;
}

void PrimalSolver::RowGroup::Clear() { num_nodes = 0; }

bool PrimalSolver::RowGroup::Matches(const ConstraintRow& row) const {
  if (num_nodes == 0 || row.body != body || row.num_nodes + row.num_nodes2 != num_nodes)
    return false;
  // Rows of one element touch exactly its nodes.
  if ((row.body2 < 0 ? row.element : -1) != element) return false;
  if (element >= 0) return true;
  for (int n = 0; n < row.num_nodes; ++n)
    if (row.nodes[n] != nodes[n]) return false;
  for (int n = 0; n < row.num_nodes2; ++n)
    if (row.nodes2[n] != nodes[row.num_nodes + n]) return false;
  return true;
}

void PrimalSolver::RowGroup::Start(const ConstraintRow& row) {
  body = row.body;
  element = row.body2 < 0 ? row.element : -1;
  num_nodes = 0;
  row.ForEachEntry([&](int, int block, const Vec3&) { nodes[num_nodes++] = block; });
  block.setZero(3 * num_nodes, 3 * num_nodes);
}

void PrimalSolver::RowGroup::Add(const ConstraintRow& row, double scale) {
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6 * kMaxRowNodes, 1> J(3 * num_nodes);
  int n = 0;
  row.ForEachEntry([&](int, int, const Vec3& Jn) { J.segment<3>(3 * n++) = Jn; });
  block.noalias() += scale * J * J.transpose();
}

void PrimalSolver::RowGroup::Scatter(const std::vector<IslandBody*>& bodies) {
  if (num_nodes == 0) return;
  if (element >= 0) {
    bodies[body]->AddNewtonElementBlock(element, nodes.data(), block);
    num_nodes = 0;
    return;
  }
  for (int a = 0; a < num_nodes; ++a)
    for (int b = 0; b < num_nodes; ++b)
      bodies[body]->AddNewtonBlock(nodes[a], nodes[b], block.block<3, 3>(3 * a, 3 * b));
  num_nodes = 0;
}

void PrimalSolver::AddRowHessianTimes(const std::vector<VecX>& u, std::vector<VecX>& out) const {
  for (int c = 0; c < rows_.size(); ++c) {
    const ConstraintRow& row = rows_[c];
    if (row.friction_of == 2) continue;
    if (row.friction_of == 1) {
      const Eigen::Vector2d ju(rows_.CalcRowVelocity(c, u), rows_.CalcRowVelocity(c + 1, u));
      const Eigen::Vector2d f = rho_[c] * (d_disk_[c] * ju);
      for (int p = 0; p < 2; ++p)
        rows_[c + p].ForEachEntry([&](int body, int block, const Vec3& J) {
          out[body].segment<3>(3 * block) += f[p] * J;
        });
      continue;
    }
    if (d_unit_[c] == 0.0) continue;
    const double f = rho_[c] * d_unit_[c] * rows_.CalcRowVelocity(c, u);
    row.ForEachEntry(
        [&](int body, int block, const Vec3& J) { out[body].segment<3>(3 * block) += f * J; });
  }
}

void PrimalSolver::ApplyHessian(const std::vector<IslandBody*>& bodies, const std::vector<VecX>& u,
                                std::vector<VecX>& out) {
  for (size_t b = 0; b < bodies.size(); ++b) bodies[b]->ApplySystemMatrix(u[b], out[b]);
  curvature_.AddTimes(u, out);
  AddRowHessianTimes(u, out);
  for (size_t b = 0; b < bodies.size(); ++b)
    for (int i = 0; i < bodies[b]->num_blocks(); ++i)
      if (!bodies[b]->is_free_block(i)) out[b].segment<3>(3 * i).setZero();
}

int PrimalSolver::SolveNewtonStep(const std::vector<IslandBody*>& bodies,
                                  const PrimalSettings& settings) {
  const size_t nb = bodies.size();
  // Local rows only and fresh factors: H = N, one solve per body.
  for (size_t b = 0; b < nb; ++b) {
    d_[b] = -grad_[b];
    bodies[b]->SolveNewton(d_[b]);
  }
  if (!coupled_ && !any_stale_) return 1;
  // Coupled or kept factors: PCG on H d = -grad from d = N^-1 (-grad), preconditioner N^-1 (a
  // kept factor: to the looser stale tolerance, within the refactor budget).
  const bool only_stale = any_stale_ && !coupled_;
  const double tolerance = any_stale_ ? settings.stale_pcg_tolerance : settings.pcg_tolerance;
  const int max_iterations =
      only_stale ? std::max(1, static_cast<int>(stale_budget_)) : settings.max_pcg_iterations;
  ApplyHessian(bodies, d_, hp_);
  for (size_t b = 0; b < nb; ++b) r_[b] = -grad_[b] - hp_[b];
  const double rhs_norm = std::sqrt(Dot(grad_, grad_));
  for (size_t b = 0; b < nb; ++b) {
    z_[b] = r_[b];
    bodies[b]->SolveNewton(z_[b]);
    p_[b] = z_[b];
  }
  double rz = Dot(r_, z_);
  int it = 1;
  for (; it <= max_iterations; ++it) {
    if (std::sqrt(Dot(r_, r_)) <= tolerance * rhs_norm || rz <= 0.0) break;
    ApplyHessian(bodies, p_, hp_);
    const double php = Dot(p_, hp_);
    if (php <= 0.0) break;
    const double alpha = rz / php;
    for (size_t b = 0; b < nb; ++b) {
      d_[b] += alpha * p_[b];
      r_[b] -= alpha * hp_[b];
      z_[b] = r_[b];
      bodies[b]->SolveNewton(z_[b]);
    }
    const double rz_next = Dot(r_, z_);
    const double beta = rz_next / rz;
    rz = rz_next;
    for (size_t b = 0; b < nb; ++b) p_[b] = z_[b] + beta * p_[b];
  }
  if (any_stale_ && it > stale_budget_) refactor_next_ = true;
  return it;
}

void PrimalSolver::CalcSlope(double alpha, double a0, double a1, double& slope,
                             double& curvature) const {
  // psi'(alpha) = a0 + alpha a1 - sum_c s_c Proj_c(y_c - alpha rho_c s_c);
  // psi''(alpha) = a1 + sum_c rho_c s_c^T D_c s_c.
  slope = a0 + alpha * a1;
  curvature = a1;
  for (int c = 0; c < rows_.size(); ++c) {
    const ConstraintRow& row = rows_[c];
    if (row.friction_of == 2 || (s_[c] == 0.0 && row.friction_of == 0)) continue;
    if (row.friction_of == 1) {
      const Eigen::Vector2d s(s_[c], s_[c + 1]);
      const double radius = row.mu * std::max(0.0, lambda_bar_[c - 1]);
      const Eigen::Vector2d y(lambda_bar_[c] - rho_[c] * (jv_[c] + alpha * s_[c]),
                              lambda_bar_[c + 1] - rho_[c] * (jv_[c + 1] + alpha * s_[c + 1]));
      Eigen::Matrix2d D;
      const Eigen::Vector2d t = ProjectOnDisk(y, radius, &D);
      slope -= s.dot(t);
      curvature += rho_[c] * s.dot(D * s);
      continue;
    }
    double D = 0.0;
    const double y = lambda_bar_[c] - rho_[c] * (g0_[c] + jv_[c] + alpha * s_[c]);
    slope -= s_[c] * ProjectOnInterval(y, LowerBound(row), UpperBound(row), &D);
    curvature += rho_[c] * D * s_[c] * s_[c];
  }
}

double PrimalSolver::SearchModelLine(const std::vector<IslandBody*>& bodies, double a0) {
  const size_t nb = bodies.size();
  // a0 = d^T A(v - v*) (+ d^T G (v - v_lin) on a model step), a1 = d^T (A + G) d, s_c = J_c d.
  for (size_t b = 0; b < nb; ++b) bodies[b]->ApplySystemMatrix(d_[b], hp_[b]);
  line_dAd_ = Dot(d_, hp_);
  line_a0_ = a0;
  curvature_.AddTimes(d_, hp_);
  const double a1 = Dot(d_, hp_);
  for (int c = 0; c < rows_.size(); ++c) s_[c] = rows_.CalcRowVelocity(c, d_);
  // psi is convex along d: bracket the root of psi' and close in by safeguarded Newton.
  double slope, curvature;
  CalcSlope(0.0, a0, a1, slope, curvature);
  if (slope >= 0.0) return 0.0;  // not a descent direction (round-off at the minimum)
  const double slope0 = slope;
  double lo = 0.0, hi = 1.0;
  CalcSlope(hi, a0, a1, slope, curvature);
  for (int grow = 0; slope < 0.0 && grow < 20; ++grow) {
    lo = hi;
    hi *= 2.0;
    CalcSlope(hi, a0, a1, slope, curvature);
  }
  if (slope < 0.0) return hi;
  double alpha = hi;
  for (int it = 0; it < 50; ++it) {
    if (std::abs(slope) <= 1e-12 * std::abs(slope0)) break;
    if (slope > 0.0)
      hi = alpha;
    else
      lo = alpha;
    double next = curvature > 0.0 ? alpha - slope / curvature : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    alpha = next;
    CalcSlope(alpha, a0, a1, slope, curvature);
    if (hi - lo <= 1e-14 * hi) break;
  }
  return alpha;
}

double PrimalSolver::CalcMerit(const std::vector<IslandBody*>& bodies, const std::vector<VecX>& v) {
  // Phi = 1/2 ||v - v*||_A^2 + sum_c P_c(y_c) / rho_c. A (v - v*) is kept for the certificate and
  // the gradient at the same v (a_dv_); at v* the energy is 0 without a product.
  double energy = 0.0;
  bool at_v_star = true;
  for (size_t b = 0; b < bodies.size(); ++b) at_v_star = at_v_star && v[b] == bodies[b]->v_star();
  if (!at_v_star) {
    if (!AreSameVelocities(a_dv_v_, v)) {
      CalcVelocityChangeMomentum(bodies, v, a_dv_);
      a_dv_v_ = v;
    }
    for (size_t b = 0; b < bodies.size(); ++b) {
      work_[b] = v[b] - bodies[b]->v_star();
      energy += 0.5 * work_[b].dot(a_dv_[b]);
    }
  }
  return energy + CalcRowMerit(v);
}

double PrimalSolver::CalcRowMerit(const std::vector<VecX>& v) const {
  // sum_c P_c(y_c) / rho_c with g_c = C_c/h (friction: J_t v).
  double phi = 0.0;
  for (int c = 0; c < rows_.size(); ++c) {
    const ConstraintRow& row = rows_[c];
    if (rho_[c] <= 0.0 || row.friction_of == 2) continue;
    if (row.friction_of == 1) {
      const double radius = row.mu * std::max(0.0, lambda_bar_[c - 1]);
      const Eigen::Vector2d y(lambda_bar_[c] - rho_[c] * rows_.CalcRowVelocity(c, v),
                              lambda_bar_[c + 1] - rho_[c] * rows_.CalcRowVelocity(c + 1, v));
      const double norm = y.norm();
      phi += (norm <= radius ? 0.5 * norm * norm : radius * norm - 0.5 * radius * radius) / rho_[c];
      continue;
    }
    const double y = lambda_bar_[c] - rho_[c] * (g0_[c] + rows_.CalcRowVelocity(c, v));
    const double lo = LowerBound(row), hi = UpperBound(row);
    double p = 0.5 * y * y;  // P(y) = integral_0^y Proj = y^2/2 inside [lo, hi], linear outside
    if (y < lo) p = lo * y - 0.5 * lo * lo;
    if (y > hi) p = hi * y - 0.5 * hi * hi;
    phi += p / rho_[c];
  }
  return phi;
}

void PrimalSolver::CollectRowsAt(double h, const std::vector<IslandBody*>& bodies,
                                 const std::vector<ConstraintSource*>& sources,
                                 const std::vector<VecX>& v, const SqpSettings& settings,
                                 StepStats& stats) {
  const auto t = std::chrono::steady_clock::now();
  const double distance_scale = settings.CalcDistanceScale();
  violation_ = rows_.Collect(h, bodies, sources, v, distance_scale);
  rows_.WarmStart(iterate_, lambda_bar_);
  CalcPenalties(h, bodies, settings.primal);
  for (size_t b = 0; b < bodies.size(); ++b) v_[b] = v[b];
  LinearizeRows(h, bodies);
  jv_.resize(rows_.size());
  s_.setZero(rows_.size());
  stats.ms_rows += MsSince(t);
}

double PrimalSolver::CalcModelMerit(const std::vector<IslandBody*>& bodies) {
  const double phi = CalcMerit(bodies, v_);  // the rows' terms are the model's: g0_, J of v_lin
  for (size_t b = 0; b < bodies.size(); ++b) {
    work_[b] = v_[b] - model_base_[b];
    model_gw_[b].setZero(work_[b].size());
  }
  curvature_.AddTimes(work_, model_gw_);
  for (size_t b = 0; b < bodies.size(); ++b)
    for (int i = 0; i < bodies[b]->num_blocks(); ++i)
      if (!bodies[b]->is_free_block(i)) model_gw_[b].segment<3>(3 * i).setZero();
  return phi + 0.5 * Dot(work_, model_gw_);
}

double PrimalSolver::StepOnModel(double alpha, const std::vector<IslandBody*>& bodies,
                                 const PrimalSettings& settings, StepStats& stats) {
  // The model keeps the rows, rho, lambda_bar and G of v_lin: g_c(u) = g0_c + J_c u (g0_ holds),
  // so Proj(y(u)), D and grad Phi at u are the plain ones plus G (u - v_lin). Only D changes
  // from H's: PCG preconditioned by H's factor solves it in a few iterations.
  const size_t nb = bodies.size();
  model_base_ = v_;
  model_gw_.resize(nb);
  const double phi_start = CalcModelMerit(bodies);
  for (size_t b = 0; b < nb; ++b) v_[b] += alpha * d_[b];
  const bool refactor_next = refactor_next_;
  for (int step = 0; step < settings.max_model_steps && alpha < settings.model_step_alpha; ++step) {
    CalcProjectedMultipliers();
    CalcGradient(bodies);
    CalcModelMerit(bodies);  // for model_gw_ = G (v - v_lin)
    for (size_t b = 0; b < nb; ++b) grad_[b] += model_gw_[b];
    any_stale_ = true;
    stale_.assign(nb, 1);
    stale_budget_ = settings.model_pcg_iterations;
    stats.pcg_iterations += SolveNewtonStep(bodies, settings);
    if (!(Dot(grad_, d_) < 0.0)) break;
    alpha = SearchModelLine(bodies, Dot(d_, aw_) + Dot(d_, model_gw_));
    if (alpha <= 0.0) break;
    for (size_t b = 0; b < nb; ++b) v_[b] += alpha * d_[b];
  }
  refactor_next_ = refactor_next;  // the PCG budget here says nothing about H's factor
  const double decrease = phi_start - CalcModelMerit(bodies);
  v_trial_ = v_;
  v_ = model_base_;
  return decrease;
}

bool PrimalSolver::TryModelSteps(double h, double alpha, double phi0,
                                 const std::vector<IslandBody*>& bodies,
                                 const std::vector<ConstraintSource*>& sources,
                                 const SqpSettings& settings, StepStats& stats) {
  const double decrease = StepOnModel(alpha, bodies, settings.primal, stats);
  if (!(decrease > 0.0)) return false;
  CollectRowsAt(h, bodies, sources, v_trial_, settings, stats);
  // Sufficient decrease against the model's decrease (the plain step: alpha times the decrement).
  // Phi fell by less than half the model's prediction: the linearization is poor here (rows that
  // flip, kinks of the principal stretches), and model steps wander on it; the rest of the step
  // takes plain Newton steps.
  const double phi = CalcMerit(bodies, v_trial_);
  if (phi0 - phi < 0.5 * decrease) model_steps_off_ = true;
  if (phi <= phi0 - 1e-4 * decrease) return true;
  base_.Restore(*this);
  return false;
}

bool PrimalSolver::TakeNewtonStep(double h, const std::vector<IslandBody*>& bodies,
                                  const std::vector<ConstraintSource*>& sources,
                                  const SqpSettings& settings, StepStats& stats) {
  const PrimalSettings& primal = settings.primal;
  const size_t nb = bodies.size();
  CalcProjectedMultipliers();
  CalcGradient(bodies);
  if (primal.curvature)
    CollectCurvature(h, bodies, sources);
  else
    curvature_.Clear();
  ChooseFactorReuse(bodies, primal);
  try {
    stats.newton_factorizations +=
        AssembleNewtonMatrices(bodies, primal.clamp_curvature_on_failure);
  } catch (const SimulationError&) {
    // H = A + sum rho J^T D J without curvature did not factor: a kept rho was set for a J that
    // has grown since (frame terms near repeated stretches grow like 1 / (s_i - s_j)), and
    // rho J^T J outgrew A by 1e16 (the orthogonal column with 20 PGS sweeps per QP). Such rows
    // keep at most the largest growth over their Delassus value at this J, and the step is taken
    // with those penalties (docs/math.md §5.8, penalties).
    if (!CapKeptPenalties(primal)) throw;
    CalcProjectedMultipliers();
    CalcGradient(bodies);
    stats.newton_factorizations += AssembleNewtonMatrices(bodies, false);
  }
  stats.pcg_iterations += SolveNewtonStep(bodies, primal);
  stats.newton_iterations++;

  // Newton decrement -grad^T d against the scale ||v - v*||_A^2 (A(v - v*) from the gradient).
  const double decrement = -Dot(grad_, d_);
  const double scale = Dot(w_, aw_);
  if (!(decrement > primal.newton_tolerance * std::max(scale, 1e-300)) &&
      !MovesViolatedRows(h, settings))
    return false;
  last_decrement_ = decrement / std::max(scale, 1e-300);
  double alpha = SearchModelLine(bodies, Dot(d_, aw_));
  if (alpha <= 0.0) return false;
  // Armijo backtracking on the nonlinear Phi (rows re-evaluated at each trial). With w = v - v*
  // the energy at v + alpha d is 1/2 w^T A w + alpha d^T A w + alpha^2/2 d^T A d (scale = w^T A w
  // and the two products of the model line search): no product with A per trial.
  const double phi0 = 0.5 * scale + CalcRowMerit(v_);
  base_.Save(*this);
  // Islands whose rows couple bodies (rigid contacts, joints) or leave H's pattern take plain
  // steps: there H is solved by PCG already, and a model step's capped PCG left the rigid box on
  // a soft block at 2 Newton iterations per step instead of 1 (docs/math.md §5.8, model steps).
  if (primal.max_model_steps > 0 && alpha < primal.model_step_alpha && !model_steps_off_ &&
      !coupled_ &&
      std::all_of(rows_.rows().begin(), rows_.rows().end(), [](const ConstraintRow& row) {
        return !IsLimitRow(row) || row.exact_curvature;
      })) {
    model_d0_ = d_;
    const double line_a0 = line_a0_, line_dAd = line_dAd_;
    last_alpha_ = 0.0;  // a model step: the rows cut the first step short
    if (TryModelSteps(h, alpha, phi0, bodies, sources, settings, stats)) return true;
    d_ = model_d0_;  // the plain step along the first direction
    line_a0_ = line_a0;
    line_dAd_ = line_dAd;
  }
  for (int halving = 0;; ++halving) {
    for (size_t b = 0; b < nb; ++b) v_trial_[b] = base_.v[b] + alpha * d_[b];
    CollectRowsAt(h, bodies, sources, v_trial_, settings, stats);
    const double energy = 0.5 * scale + alpha * line_a0_ + 0.5 * alpha * alpha * line_dAd_;
    if (energy + CalcRowMerit(v_trial_) <= phi0 - 1e-4 * alpha * decrement) {
      last_alpha_ = alpha;
      return true;
    }
    if (halving >= settings.max_line_search_halvings) break;
    alpha *= 0.5;
  }
  // No sufficient decrease (round-off at the minimum): stay at v.
  base_.Restore(*this);
  return false;
}

bool PrimalSolver::MovesViolatedRows(double h, const SqpSettings& settings) const {
  // A decrement below newton_tolerance of ||v - v*||_A^2 says Phi is minimized to that relative
  // accuracy, not that the rows are: the finger's contact forces set that scale, and a limit row
  // violated by 2e-5 (tolerance 1e-5) changes Phi by 1e-9 of it, so the loop stopped with v short
  // of the row's answer and the multiplier iterations cycled to their cap (docs/math.md §5.8,
  // rows still moving). The loop goes on while d moves a row violated by more than the tolerance
  // by more than newton_row_move_fraction of it (C changes by h J_c d; distance rows in limit-row
  // units, as violation_).
  const double fraction = settings.primal.newton_row_move_fraction;
  if (fraction <= 0.0 || violation_ <= settings.violation_tolerance) return false;
  const double distance_scale = settings.CalcDistanceScale();
  for (int c = 0; c < rows_.size(); ++c) {
    const ConstraintRow& row = rows_[c];
    const double scale = CalcLimitUnitScale(row, distance_scale);
    if (row.friction_of > 0 || row.violation() * scale <= settings.violation_tolerance) continue;
    if (h * scale * std::abs(rows_.CalcRowVelocity(c, d_)) >
        fraction * settings.violation_tolerance)
      return true;
  }
  return false;
}

bool PrimalSolver::IsNewtonIterateCertified(const std::vector<IslandBody*>& bodies, double h,
                                            const SqpSettings& settings) {
  // (v, Proj(y(v))) is the pair the multiplier update would certify next: when it already holds,
  // the remaining Newton iterations (quadratic convergence to 1e-9 of ||v - v*||_A^2) and the
  // update's own check change nothing a user can see (docs/math.md §5.8, inexact inner solves).
  // Distance rows (contacts, joints) must hold to newton_stop_distance_factor of their
  // tolerance: a sticking contact may slip h |J_t v| <= tolerance in every step, and a rigid stack
  // stopped at the tolerance crept 15 mm in 2 s where the exact solve holds it.
  if (violation_ > settings.violation_tolerance) return false;  // its primal residual
  CalcProjectedMultipliers();
  const double distance_scale = settings.CalcDistanceScale();
  newton_kkt_ = CalcKktResidualsWithRefit(
      bodies, rows_, lambda_, v_, h, distance_scale, settings.violation_tolerance,
      settings.stationarity_tolerance, a_dv_, newton_reported_, AreSameVelocities(a_dv_v_, v_));
  a_dv_v_ = v_;
  const KktResiduals& kkt = newton_kkt_;
  if (!IsCertified(kkt, settings.violation_tolerance, settings.stationarity_tolerance))
    return false;
  const double distance_tolerance =
      settings.primal.newton_stop_distance_factor * settings.violation_tolerance;
  return kkt.max_distance_residual() <= distance_tolerance;
}

bool PrimalSolver::IsViolationStalled(double violation_before, double tolerance,
                                      const PrimalSettings& settings) const {
  // Phi's minimizer for this lambda_bar and rho is violated: once a Newton step near that
  // minimizer (relative decrement below newton_stall_decrement, alpha >= 1/2: the rows did not
  // cut it short) closes less than newton_stall_fraction of the gap to the tolerance, the remaining
  // steps converge v to that violated minimizer and only the multiplier update moves the rows on
  // (docs/math.md §5.8, inexact inner solves).
  if (settings.newton_stall_fraction <= 0.0 || violation_ <= tolerance) return false;
  if (last_alpha_ < 0.5 || last_decrement_ > settings.newton_stall_decrement) return false;
  const double gap = violation_before - tolerance;
  return gap > 0.0 &&
         std::abs(violation_before - violation_) < settings.newton_stall_fraction * gap;
}

bool PrimalSolver::WarmStartVelocities(const std::vector<IslandBody*>& bodies) {
  // v = v* + A^-1 J^T lambda_bar (the previous step's impulses on this step's rows), with the
  // factor the unconstrained solve held: only a candidate start, so a kept factor does.
  if (rows_.empty() || lambda_bar_.cwiseAbs().maxCoeff() == 0.0) return false;
  v_trial_ = v_;
  rows_.AddImpulseVelocities(bodies, lambda_bar_, work_, v_trial_);
  return true;
}

void PrimalSolver::ChooseStartVelocities(double h, const std::vector<IslandBody*>& bodies,
                                         const std::vector<ConstraintSource*>& sources,
                                         const SqpSettings& settings, StepStats& stats) {
  // Candidates: v*, the step-start velocity (v* on pinned blocks), the warm start
  // v* + A^-1 J^T lambda_bar; the one of least Phi (with its rows) is the start. Rows are at v* on
  // entry. Each candidate's Phi needs its own rows (an SVD per element near its limits), and the
  // warm start rarely wins (measured: 2 of 400 steps on the hex cantilever at 0.1 J, 3 of 100
  // on the resting slab), so it is collected only when Phi of the rows of v* linearized there
  // (the model a Newton step from v* minimizes) puts it below the best candidate so far.
  double best = CalcMerit(bodies, v_);
  const auto try_candidate = [&] {
    base_.Save(*this);
    CollectRowsAt(h, bodies, sources, v_trial_, settings, stats);
    const double phi = CalcMerit(bodies, v_);
    if (phi < best) {
      best = phi;
    } else {
      base_.Restore(*this);
    }
  };
  const bool has_warm = WarmStartVelocities(bodies);
  double warm_model = std::numeric_limits<double>::infinity();
  if (has_warm) {
    warm_v_ = v_trial_;
    warm_model = CalcMerit(bodies, warm_v_);  // the rows of v*: g_c = g0_c + J_c v
  }
  bool moved = false;
  for (size_t b = 0; b < bodies.size(); ++b) {
    const IslandBody& body = *bodies[b];
    v_trial_[b] = body.v_star();
    for (int i = 0; i < body.num_blocks(); ++i)
      if (body.is_free_block(i)) v_trial_[b].segment<3>(3 * i) = body.v_start().segment<3>(3 * i);
    moved = moved || v_trial_[b] != body.v_star();
  }
  if (moved) try_candidate();
  if (has_warm && (warm_model < best || !settings.primal.screen_warm_start)) {
    v_trial_ = warm_v_;
    try_candidate();
  }
}

bool PrimalSolver::MoveToUnconstrainedVelocity(double h, const std::vector<IslandBody*>& bodies,
                                               const std::vector<ConstraintSource*>& sources,
                                               const SqpSettings& settings, StepStats& stats) {
  bool at_v_star = true;
  for (size_t b = 0; b < bodies.size(); ++b) {
    v_trial_[b] = bodies[b]->v_star();
    at_v_star = at_v_star && v_[b] == v_trial_[b];
  }
  if (at_v_star) return false;
  CollectRowsAt(h, bodies, sources, v_trial_, settings, stats);
  return !rows_.empty();
}

void PrimalSolver::StoreCertifiedWarmStart(double violation_tolerance) {
  // The certified multipliers (reported_: lambda_bar, or the refit where lambda_bar alone did not
  // pass), except on slack limit rows (C > tolerance), which keep lambda_bar (docs/math.md §5.10,
  // warm start). A rigid box resting on a limited block settled into certifying each step just
  // under the tolerances (complementarity 9.3e-4 to 9.95e-4 against 1e-3) from the bare
  // lambda_bar, 3.9 Newton iterations per step; from the refit, 1.0. The refit's zero on slack
  // rows made the collapsing vertical_beam columns worse (max violation 0.05 -> 0.42).
  work_lambda_ = reported_;
  for (int c = 0; c < rows_.size(); ++c)
    if (IsLimitRow(rows_[c]) && rows_[c].C > violation_tolerance) work_lambda_[c] = lambda_bar_[c];
  rows_.Store(work_lambda_, iterate_);
}

void PrimalSolver::Solve(double h, const std::vector<IslandBody*>& bodies,
                         const std::vector<ConstraintSource*>& sources, const SqpSettings& settings,
                         KeyedMultipliers& warm, StepStats& stats) {
  const PrimalSettings& primal = settings.primal;
  const size_t nb = bodies.size();
  for (auto* list : {&v_, &v_trial_, &d_, &grad_, &work_, &w_, &aw_, &r_, &z_, &p_, &hp_})
    list->resize(nb);
  std::vector<VecX> start(nb);
  for (size_t b = 0; b < nb; ++b) {
    start[b] = bodies[b]->v();
    for (auto* list : {&v_, &v_trial_, &d_, &grad_, &work_, &w_, &aw_, &r_, &z_, &p_, &hp_})
      (*list)[b].setZero(start[b].size());
  }
  // (Not `c ? warm : KeyedMultipliers()`: clang 14's UBSan at -O1 reads the flag of that
  // conditional temporary uninitialized and reports a bad bool.)
  if (settings.warm_start) {
    iterate_ = warm;
  } else {
    iterate_.clear();
  }
  a_dv_v_.clear();  // this step's v* and A
  rho_kept_ = false;
  newton_certified_ = false;
  model_steps_off_ = false;
  last_violation_.clear();
  kept_growth_.clear();
  // A factor kept from the previous step may precondition this one, unless its last PCG ran past
  // the budget (refactor_next_ carried over): measured on rest_box (a rigid box on a soft block,
  // a coupled island), a kept factor from the settling phase took 170 PCG iterations per step
  // against 18 with a fresh one, step after step.
  const double distance_scale = settings.CalcDistanceScale();
  CollectRowsAt(h, bodies, sources, start, settings, stats);
  stats.violation_before = violation_;
  ChooseStartVelocities(h, bodies, sources, settings, stats);
  for (int k = 0;; ++k) {
    if (rows_.empty() && !MoveToUnconstrainedVelocity(h, bodies, sources, settings, stats)) break;
    // Certificate of (v, lambda_bar) at the rows of v.
    rows_.CountTypes(stats);
    const auto t = std::chrono::steady_clock::now();
    const double ms_rows_before = stats.ms_rows;  // row collection inside is ms_rows, not ms_solve
    // After a Newton stop on the certificate, lambda_bar = Proj(y(v)) at the same rows: its
    // residuals are the ones just computed.
    if (newton_certified_) reported_ = newton_reported_;
    const KktResiduals kkt =
        newton_certified_ ? newton_kkt_
                          : CalcKktResidualsWithRefit(bodies, rows_, lambda_bar_, v_, h,
                                                      distance_scale, settings.violation_tolerance,
                                                      settings.stationarity_tolerance, a_dv_,
                                                      reported_, AreSameVelocities(a_dv_v_, v_));
    if (!newton_certified_) a_dv_v_ = v_;
    newton_certified_ = false;
    RecordKkt(kkt, stats);
    stats.converged =
        IsCertified(kkt, settings.violation_tolerance, settings.stationarity_tolerance);
    if (stats.converged) StoreCertifiedWarmStart(settings.violation_tolerance);
    if (stats.converged || k >= primal.max_iterations) {
      stats.ms_solve += MsSince(t);
      break;
    }
    // Minimize Phi for this lambda_bar and rho, then the multiplier update
    // lambda_bar <- Proj(y(v)).
    if (primal.penalty_growth > 1.0) GrowStalledPenalties(primal, settings.violation_tolerance, k);
    KeepPenalties();
    for (int it = 0; it < primal.max_newton_iterations; ++it) {
      const double violation_before = violation_;
      if (!TakeNewtonStep(h, bodies, sources, settings, stats)) break;
      newton_certified_ =
          primal.stop_newton_on_certificate && IsNewtonIterateCertified(bodies, h, settings);
      if (newton_certified_) break;
      if (k < primal.newton_stall_iterations &&
          IsViolationStalled(violation_before, settings.violation_tolerance, primal))
        break;
    }
    if (!newton_certified_) CalcProjectedMultipliers();  // else lambda_ is Proj(y(v)) already
    lambda_bar_ = lambda_;
    rows_.Store(lambda_bar_, iterate_);
    stats.sqp_iterations = k + 1;
    stats.ms_solve += MsSince(t) - (stats.ms_rows - ms_rows_before);
  }
  if (rows_.empty()) {
    iterate_.clear();
    reported_.resize(0);
  }
  for (size_t b = 0; b < nb; ++b) bodies[b]->set_v(v_[b]);
  stats.violation_after = violation_;  // of the rows kept (a restored base point's, not a trial's)
  warm = iterate_;
  stats.islands_primal++;
}

}  // namespace taut
