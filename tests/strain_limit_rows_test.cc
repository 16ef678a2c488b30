// Strain-limit rows: FD checks of every mode's Jacobian and the claims of docs/math.md §2-§3.
#include "constraints/strain_limit_rows.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <random>
#include <vector>

namespace taut {
namespace {

const double kInf = std::numeric_limits<double>::infinity();
const double kPi = std::acos(-1.0);
constexpr StrainProjection kAllModes[] = {
    StrainProjection::kHyperbolic, StrainProjection::kOrthogonal,
    StrainProjection::kLinearInterpolation, StrainProjection::kEllipsoid};

// Paper A's rows as printed: no switch to the ellipsoid rows for equal limits, no hyperbolic
// row filter and no non-inversion floor (the tests of the paper's rules and Jacobians use every
// row).
StrainLimitSettings Paper(StrainLimitSettings settings) {
  settings.equal_limits_use_ellipsoid = false;
  settings.hyperbolic_row_band = kInf;
  settings.inversion_floor = 0.0;
  return settings;
}

// The settings without the non-inversion floor (tests of the axis rules alone).
StrainLimitSettings NoFloor(StrainLimitSettings settings) {
  settings.inversion_floor = 0.0;
  return settings;
}

// Uniformly random rotation from a normalized Gaussian quaternion.
Mat3 RandomRotation(std::mt19937* rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Quaterniond q(n(*rng), n(*rng), n(*rng), n(*rng));
  return q.normalized().toRotationMatrix();
}

// Rest tet: a perturbed regular tet (random when rng is set); X_out receives its nodes.
TetRestRows MakeRestRows(std::mt19937* rng, std::array<Vec3, 4>* X_out) {
  std::uniform_real_distribution<double> u(-0.15, 0.15);
  std::array<Vec3, 4> X = {Vec3(1, 1, 1), Vec3(1, -1, -1), Vec3(-1, 1, -1), Vec3(-1, -1, 1)};
  for (Vec3& p : X) p = 0.3 * (rng ? p + Vec3(u(*rng), u(*rng), u(*rng)) : p);
  Mat3 X0;
  for (int c = 0; c < 3; ++c) X0.col(c) = X[c] - X[3];
  if (X0.determinant() < 0) std::swap(X[0], X[1]);
  for (int c = 0; c < 3; ++c) X0.col(c) = X[c] - X[3];
  const Mat3 inv = X0.inverse();
  TetRestRows r;
  for (int n = 0; n < 3; ++n) r[n] = inv.row(n).transpose();
  r[3] = -(r[0] + r[1] + r[2]);
  *X_out = X;
  return r;
}

// Node positions x_n = G X_n + t.
TetPositions PositionsFromG(const Mat3& G, const std::array<Vec3, 4>& X, const Vec3& t) {
  TetPositions x;
  for (int n = 0; n < 4; ++n) x[n] = G * X[n] + t;
  return x;
}

// A single tet whose deformation gradient is G.
struct Tet {
  TetRestRows r;
  TetPositions x;
};
Tet TetFromG(const Mat3& G) {
  std::array<Vec3, 4> X;
  Tet tet;
  tet.r = MakeRestRows(nullptr, &X);
  tet.x = PositionsFromG(G, X, Vec3(0.5, -1.0, 2.0));
  return tet;
}

// All candidate rows (tau = +inf) of one tet.
std::vector<StrainLimitRow> AllRows(const TetRestRows& r, const TetPositions& x, const Mat3& Q,
                                    StrainLimitParams params) {
  params.activation_margin = kInf;
  std::vector<StrainLimitRow> rows;
  AppendStrainLimitRows(3, r, x, Q, params, &rows);
  return rows;
}

// C of the row with `key`, or NaN when the perturbed state has no such row.
double FindC(const std::vector<StrainLimitRow>& rows, const StrainLimitKey& key) {
  for (const StrainLimitRow& row : rows)
    if (row.key == key) return row.C;
  return std::numeric_limits<double>::quiet_NaN();
}

// Central FD of C for the row with `key`; false when the key is missing in a perturbed state.
bool CalcFdJacobian(const TetRestRows& r, const TetPositions& x, const Mat3& Q,
                    const StrainLimitParams& params, const StrainLimitKey& key, double h,
                    Vec12* J) {
  for (int c = 0; c < 12; ++c) {
    TetPositions xp = x, xm = x;
    xp[c / 3][c % 3] += h;
    xm[c / 3][c % 3] -= h;
    const double Cp = FindC(AllRows(r, xp, Q, params), key);
    const double Cm = FindC(AllRows(r, xm, Q, params), key);
    if (std::isnan(Cp) || std::isnan(Cm)) return false;
    (*J)[c] = (Cp - Cm) / (2 * h);
  }
  return true;
}

// Smallest |s_a - s_b|, |s_a + s_b| and |s_a - 1|: distance to a singularity or a row switch.
double MinGap(const Vec3& s) {
  double gap = 1e300;
  for (int a = 0; a < 3; ++a) {
    gap = std::min(gap, std::abs(s[a] - 1.0));
    for (int b = a + 1; b < 3; ++b)
      gap = std::min({gap, std::abs(s[a] - s[b]), std::abs(s[a] + s[b])});
  }
  return gap;
}

double Percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  return v[static_cast<size_t>(p * (v.size() - 1))];
}

// Random per-axis limits, each side unlimited with probability 1/4; every 4th call isotropic.
StrainLimitParams RandomParams(std::mt19937* rng, StrainProjection mode, int trial) {
  std::uniform_real_distribution<double> lo(0.6, 0.97), hi(1.03, 1.4), coin(0.0, 1.0);
  Vec3 s_min, s_max;
  for (int j = 0; j < 3; ++j) {
    s_min[j] = coin(*rng) < 0.25 ? 0.0 : lo(*rng);
    s_max[j] = coin(*rng) < 0.25 ? kUnlimitedStretch : hi(*rng);
  }
  if (trial % 4 == 0) {
    s_min.setConstant(s_min[0] == 0.0 ? 0.9 : s_min[0]);
    s_max.setConstant(std::isinf(s_max[0]) ? 1.1 : s_max[0]);
  }
  StrainLimitSettings settings = Paper(StrainLimitSettings::PerAxis(s_min, s_max, mode));
  settings.svd_gap_epsilon = 0.0;  // exact derivatives for the FD comparison
  settings.Validate(1, "test");
  return CalcStrainLimitParams(settings);
}

// Random G = U diag(s) V^T, s ~ U[0.5, 1.5], inverted (s_3 < 0) 20 % of the time.
Mat3 RandomG(std::mt19937* rng) {
  std::uniform_real_distribution<double> u(0.5, 1.5), coin(0.0, 1.0);
  Vec3 s(u(*rng), u(*rng), u(*rng));
  if (coin(*rng) < 0.2) s[2] = -s[2];
  return RandomRotation(rng) * s.asDiagonal() * RandomRotation(rng).transpose();
}

TEST(StrainLimitRowsTest, JacobianMatchesFdOnRandomStatesForEveryMode) {
  for (const StrainProjection mode : kAllModes) {
    std::mt19937 rng(10 + static_cast<int>(mode));
    std::vector<double> errors, frozen_errors;
    int skipped_keys = 0, kink_rows = 0;
    for (int trial = 0; trial < 600; ++trial) {
      std::array<Vec3, 4> X;
      const TetRestRows r = MakeRestRows(&rng, &X);
      const TetPositions x = PositionsFromG(RandomG(&rng), X, Vec3(0.1, 0.2, 0.3));
      const Mat3 Q = RandomRotation(&rng);
      StrainLimitParams params = RandomParams(&rng, mode, trial);
      const SignedSvd svd = CalcSignedSvd(CalcTetDeformationGradient(r, x));
      const double h = std::min(1e-6, 1e-3 * MinGap(svd.s));
      const Mat3 V_prime = Q.transpose() * svd.V;
      std::vector<StrainLimitRow> rows = AllRows(r, x, Q, params);
      params.freeze_frame_jacobian = true;
      const std::vector<StrainLimitRow> frozen = AllRows(r, x, Q, params);
      params.freeze_frame_jacobian = false;
      ASSERT_EQ(rows.size(), frozen.size());
      for (size_t k = 0; k < rows.size(); ++k) {
        const StrainLimitRow& row = rows[k];
        const bool per_axis =
            mode == StrainProjection::kHyperbolic || mode == StrainProjection::kOrthogonal;
        if (per_axis && std::abs(V_prime(row.key.axis, row.principal_index)) < 1e-4) {
          ++kink_rows;  // the FD stencil may straddle the |V'_ji| kink
          continue;
        }
        Vec12 J_fd;
        if (!CalcFdJacobian(r, x, Q, params, row.key, h, &J_fd)) {
          ++skipped_keys;
          continue;
        }
        ASSERT_GT(row.J.norm(), 1e-6);
        ASSERT_TRUE(row.J.allFinite());
        errors.push_back((row.J - J_fd).norm() / J_fd.norm());
        frozen_errors.push_back((frozen[k].J - J_fd).norm() / J_fd.norm());
      }
    }
    std::printf(
        "[ %s ] %zu rows: rel err median %.2e p99 %.2e max %.2e (frozen frame: median "
        "%.2e max %.2e); kink rows %d, key changes %d\n",
        GetStrainProjectionName(mode), errors.size(), Percentile(errors, 0.5),
        Percentile(errors, 0.99), Percentile(errors, 1.0), Percentile(frozen_errors, 0.5),
        Percentile(frozen_errors, 1.0), kink_rows, skipped_keys);
    EXPECT_GT(errors.size(), 1000u);
    EXPECT_LT(Percentile(errors, 0.5), 1e-8);
    EXPECT_LT(Percentile(errors, 1.0), 1e-4);
    // The frame term matters: the frozen Jacobian is not the derivative.
    EXPECT_GT(Percentile(frozen_errors, 0.5), 1e-2);
    EXPECT_LT(skipped_keys, 10);
  }
}

// docs/math.md §2.2: exact down to tiny gaps when the FD step is h = 1e-3 gap (gap clamp off).
TEST(StrainLimitRowsTest, JacobianMatchesFdNearRepeatedValues) {
  std::mt19937 rng(20);
  for (const StrainProjection mode : kAllModes) {
    double worst = 0.0;
    for (const bool inverted_pair : {false, true}) {
      for (const double delta : {1e-2, 1e-4, 1e-6}) {
        const Vec3 s = inverted_pair ? Vec3(1.3, 0.6, -0.6 + delta) : Vec3(1.2, 1.2 - delta, 0.8);
        std::array<Vec3, 4> X;
        const TetRestRows r = MakeRestRows(&rng, &X);
        const Mat3 G = RandomRotation(&rng) * s.asDiagonal() * RandomRotation(&rng).transpose();
        const TetPositions x = PositionsFromG(G, X, Vec3::Zero());
        const Mat3 Q = RandomRotation(&rng);
        StrainLimitSettings settings =
            StrainLimitSettings::PerAxis(Vec3(0.7, 0.0, 0.9), Vec3(1.05, 1.3, kInf), mode);
        settings.svd_gap_epsilon = 0.0;
        const StrainLimitParams params = CalcStrainLimitParams(settings);
        const std::vector<StrainLimitRow> rows = AllRows(r, x, Q, params);
        ASSERT_FALSE(rows.empty());
        for (const StrainLimitRow& row : rows) {
          Vec12 J_fd;
          ASSERT_TRUE(CalcFdJacobian(r, x, Q, params, row.key, 1e-3 * delta, &J_fd));
          ASSERT_GT(row.J.norm(), 1e-6);
          worst = std::max(worst, (row.J - J_fd).norm() / J_fd.norm());
        }
      }
    }
    std::printf("[ %s near-repeated, h = 1e-3 gap ] max rel err %.2e\n",
                GetStrainProjectionName(mode), worst);
    EXPECT_LT(worst, 1e-4);
  }
}

// R1: with the default epsilon the Jacobian is unchanged unless a gap of an emitting principal
// direction is below epsilon.
TEST(StrainLimitRowsTest, GapClampChangesOnlyRowsWithSmallGaps) {
  std::mt19937 rng(30);
  int unchanged = 0, changed = 0;
  for (int trial = 0; trial < 400; ++trial) {
    std::array<Vec3, 4> X;
    const TetRestRows r = MakeRestRows(&rng, &X);
    const TetPositions x = PositionsFromG(RandomG(&rng), X, Vec3::Zero());
    const Mat3 Q = RandomRotation(&rng);
    StrainLimitParams params = RandomParams(&rng, StrainProjection::kHyperbolic, 1);
    const std::vector<StrainLimitRow> exact = AllRows(r, x, Q, params);
    params.svd_gap_epsilon = 1e-2;
    const std::vector<StrainLimitRow> clamped = AllRows(r, x, Q, params);
    const Vec3 s = CalcSignedSvd(CalcTetDeformationGradient(r, x)).s;
    ASSERT_EQ(exact.size(), clamped.size());
    for (size_t k = 0; k < exact.size(); ++k) {
      EXPECT_EQ(exact[k].C, clamped[k].C);
      const double diff = (exact[k].J - clamped[k].J).norm();
      if (IsSvdGapClampActive(s, exact[k].principal_index, 1e-2)) {
        ++changed;
        EXPECT_GT(diff, 0.0);
      } else {
        ++unchanged;
        EXPECT_EQ(diff, 0.0);
      }
    }
  }
  std::printf("[ clamp eps = 1e-2 ] rows changed %d, unchanged %d\n", changed, unchanged);
  EXPECT_GT(changed, 0);
  EXPECT_GT(unchanged, 10 * changed);
}

// R2: V'_ji = 0 exactly gives sgn 0, finite rows and no crash in every mode.
TEST(StrainLimitRowsTest, KinkAtZeroFrameEntryIsFinite) {
  const Tet tet = TetFromG(Vec3(1.1, 1.02, 0.97).asDiagonal());
  for (const StrainProjection mode : kAllModes) {
    const StrainLimitParams params = CalcStrainLimitParams(
        NoFloor(StrainLimitSettings::PerAxis(Vec3(0.9, 0.0, 0.9), Vec3(1.05, kInf, 1.2), mode)));
    const std::vector<StrainLimitRow> rows = AllRows(tet.r, tet.x, Mat3::Identity(), params);
    ASSERT_FALSE(rows.empty());
    for (const StrainLimitRow& row : rows) {
      EXPECT_TRUE(std::isfinite(row.C) && row.J.allFinite()) << GetStrainProjectionName(mode);
      if (mode == StrainProjection::kHyperbolic && row.key.axis != row.principal_index) {
        EXPECT_EQ(row.C, 1.0);  // the kink is interior: C = 1 where V'_ji = 0
        EXPECT_EQ(row.J.norm(), 0.0);
      }
    }
  }
}

// docs/math.md §3.5: with a single limited axis the ellipsoid rows equal the hyperbolic rows.
TEST(StrainLimitRowsTest, EllipsoidEqualsHyperbolicForSingleLimitedAxis) {
  std::mt19937 rng(40);
  for (int trial = 0; trial < 200; ++trial) {
    std::array<Vec3, 4> X;
    const TetRestRows r = MakeRestRows(&rng, &X);
    const TetPositions x = PositionsFromG(RandomG(&rng), X, Vec3::Zero());
    const Mat3 Q = RandomRotation(&rng);
    const int j = trial % 3;
    Vec3 s_min = Vec3::Zero(), s_max = Vec3::Constant(kInf);
    s_min[j] = 0.9;
    s_max[j] = 1.1;
    const auto rows_of = [&](StrainProjection mode) {
      return AllRows(
          r, x, Q, CalcStrainLimitParams(Paper(StrainLimitSettings::PerAxis(s_min, s_max, mode))));
    };
    const std::vector<StrainLimitRow> hyper = rows_of(StrainProjection::kHyperbolic);
    const std::vector<StrainLimitRow> ellip = rows_of(StrainProjection::kEllipsoid);
    ASSERT_EQ(hyper.size(), ellip.size());
    ASSERT_FALSE(hyper.empty());
    for (size_t k = 0; k < hyper.size(); ++k) {
      EXPECT_EQ(hyper[k].principal_index, ellip[k].principal_index);
      EXPECT_EQ(hyper[k].key.bound, ellip[k].key.bound);
      EXPECT_NEAR(hyper[k].C, ellip[k].C, 1e-12);
      EXPECT_LT((hyper[k].J - ellip[k].J).norm(), 1e-10 * hyper[k].J.norm());
    }
  }
}

// Effective stretch limit along v_1 for isotropic limits 1 +- d: the s_1 at which min C = 0
// (paper: the mode's own rule, no switch of equal hyperbolic limits to the ellipsoid rows).
double EffectiveLimit(StrainProjection mode, const Mat3& Q, const Mat3& V, double d,
                      bool paper = true) {
  StrainLimitSettings settings = StrainLimitSettings::Isotropic(1.0 - d, 1.0 + d, mode);
  const StrainLimitParams params = CalcStrainLimitParams(paper ? Paper(settings) : settings);
  double lo = 1.0, hi = 1.0 + 3.0 * d;
  for (int it = 0; it < 60; ++it) {
    const double s1 = 0.5 * (lo + hi);
    const Tet tet = TetFromG(V * Vec3(s1, 1.0, 1.0).asDiagonal() * V.transpose());
    (CalcStrainLimitViolation(tet.r, tet.x, Q, params) > 0.0 ? hi : lo) = s1;
  }
  return lo - 1.0;
}

// docs/math.md §3.6 / §6 A3: ellipsoid gives exactly d in any frame, hyperbolic d / max_j |V'_j1|,
// up to sqrt(3) d when v_1 is the frame diagonal.
TEST(StrainLimitRowsTest, IsotropicLimitsEllipsoidExactHyperbolicUpToSqrt3) {
  std::mt19937 rng(50);
  const double d = 0.05;
  for (int trial = 0; trial < 100; ++trial) {
    const Mat3 Q = RandomRotation(&rng);
    const Mat3 V = RandomRotation(&rng);
    EXPECT_NEAR(EffectiveLimit(StrainProjection::kEllipsoid, Q, V, d), d, 1e-9);
    const double max_entry = (Q.transpose() * V).col(0).cwiseAbs().maxCoeff();
    const double hyper = EffectiveLimit(StrainProjection::kHyperbolic, Q, V, d);
    EXPECT_NEAR(hyper, d / max_entry, 1e-9);
    EXPECT_GE(hyper, d - 1e-9);
    EXPECT_LE(hyper, std::sqrt(3.0) * d + 1e-9);
  }
  // v_1 along the frame diagonal (1,1,1)/sqrt(3): hyperbolic allows sqrt(3) d = 8.66 %.
  const Mat3 Q = RandomRotation(&rng);
  const Vec3 diag = Q * Vec3::Ones().normalized();
  Mat3 V;
  V.col(0) = diag;
  V.col(1) = diag.unitOrthogonal();
  V.col(2) = diag.cross(V.col(1));
  EXPECT_NEAR(EffectiveLimit(StrainProjection::kHyperbolic, Q, V, d), std::sqrt(3.0) * d, 1e-9);
  EXPECT_NEAR(EffectiveLimit(StrainProjection::kEllipsoid, Q, V, d), d, 1e-9);
  // By default equal hyperbolic limits are evaluated as the ellipsoid rows: exactly d.
  EXPECT_NEAR(EffectiveLimit(StrainProjection::kHyperbolic, Q, V, d, /*paper=*/false), d, 1e-9);
}

// Beam load path of docs/math.md §3.6: G = Rz(phi) diag(a(1 + 1e-3), a) Rz(phi)^T (+) (1 - eps).
Mat3 BeamG(double phi_deg, double eps) {
  const double a = 1.0 + 0.3 * eps;
  const Mat3 R = Eigen::AngleAxisd(phi_deg * kPi / 180.0, Vec3::UnitZ()).toRotationMatrix();
  Mat3 G = R * Vec3(a * (1.0 + 1e-3), a, 1.0).asDiagonal() * R.transpose();
  G(2, 2) = 1.0 - eps;
  return G;
}

// Beam limits: e1 transverse in [0.95, 1.05], e2 transverse and e3 vertical unlimited.
StrainLimitParams BeamParams(StrainProjection mode, double cap) {
  StrainLimitSettings settings =
      Paper(StrainLimitSettings::PerAxis(Vec3(0.95, 0.0, 0.0), Vec3(1.05, kInf, kInf), mode));
  settings.unlimited_s_max_cap = cap;
  settings.Validate(1, "beam");
  return CalcStrainLimitParams(settings);
}

// First compression eps in (0, 0.999] that violates a limit (scan, then bisection); 1 = never.
double FirstViolation(const StrainLimitParams& params, double phi_deg) {
  const auto violated = [&](double eps) {
    const Tet tet = TetFromG(BeamG(phi_deg, eps));
    return CalcStrainLimitViolation(tet.r, tet.x, Mat3::Identity(), params) > 0.0;
  };
  double lo = 0.0;
  for (double eps = 1e-3; eps < 0.9995; eps += 1e-3) {
    if (!violated(eps)) {
      lo = eps;
      continue;
    }
    double hi = eps;
    for (int it = 0; it < 40; ++it) (violated(0.5 * (lo + hi)) ? hi : lo) = 0.5 * (lo + hi);
    return hi;
  }
  return 1.0;
}

// docs/math.md §3.6 beam table: hyperbolic, LI (caps 2 and 10) and ellipsoid (= hyperbolic).
TEST(StrainLimitRowsTest, SingleTetBeamTableOfMathNote) {
  struct Entry {
    double phi, hyper, strain, li2, li10;
  };
  const Entry table[] = {{0.0, 0.163, 0.0500, 0.163, 0.163},
                         {10.0, 0.166, 0.0507, 0.299, 1.0},
                         {22.5, 0.177, 0.0540, 0.781, 1.0},
                         {45.0, 0.232, 0.0702, 1.0, 1.0}};
  for (const Entry& e : table) {
    const double hyper = FirstViolation(BeamParams(StrainProjection::kHyperbolic, 2.0), e.phi);
    const double ellip = FirstViolation(BeamParams(StrainProjection::kEllipsoid, 2.0), e.phi);
    const double li2 =
        FirstViolation(BeamParams(StrainProjection::kLinearInterpolation, 2.0), e.phi);
    const double li10 =
        FirstViolation(BeamParams(StrainProjection::kLinearInterpolation, 10.0), e.phi);
    const Tet tet = TetFromG(BeamG(e.phi, hyper));
    const double strain = CalcMaterialAxisStrain(tet.r, tet.x, Vec3::UnitX());
    std::printf(
        "[ beam phi %4.1f ] hyperbolic %.4f (%.2f %%), ellipsoid %.4f, LI cap 2 %.4f, "
        "LI cap 10 %.4f\n",
        e.phi, hyper, 100 * strain, ellip, li2, li10);
    EXPECT_NEAR(hyper, e.hyper, 1e-3);
    EXPECT_NEAR(strain, e.strain, 1e-4);
    EXPECT_NEAR(ellip, hyper, 1e-9);
    EXPECT_NEAR(li2, e.li2, 1e-3);
    EXPECT_NEAR(li10, e.li10, 1e-3);
  }
}

// docs/math.md §3.6 / §6 A1: orthogonal projection is violated by any deformation on the beam path,
// and even for isotropic limits with V = I.
TEST(StrainLimitRowsTest, OrthogonalProjectionViolatesAtAnyDeformation) {
  for (const double phi : {0.0, 10.0, 22.5, 45.0}) {
    for (const double eps : {1e-6, 1e-3}) {
      const Tet tet = TetFromG(BeamG(phi, eps));
      const StrainLimitParams params = BeamParams(StrainProjection::kOrthogonal, 2.0);
      EXPECT_GT(CalcStrainLimitViolation(tet.r, tet.x, Mat3::Identity(), params), 0.0);
      EXPECT_EQ(CalcStrainLimitViolation(tet.r, tet.x, Mat3::Identity(),
                                         BeamParams(StrainProjection::kHyperbolic, 2.0)),
                0.0);
    }
  }
  const Tet tet = TetFromG(Vec3(1.001, 0.999, 1.0005).asDiagonal());
  const auto isotropic = [](StrainProjection mode) {
    return CalcStrainLimitParams(StrainLimitSettings::Isotropic(0.95, 1.05, mode));
  };
  EXPECT_GT(CalcStrainLimitViolation(tet.r, tet.x, Mat3::Identity(),
                                     isotropic(StrainProjection::kOrthogonal)),
            0.0);
  EXPECT_EQ(CalcStrainLimitViolation(tet.r, tet.x, Mat3::Identity(),
                                     isotropic(StrainProjection::kHyperbolic)),
            0.0);
}

// R3: keys follow the principal directions, not the index i, when s_1 and s_2 swap order.
TEST(StrainLimitRowsTest, KeysStableWhenSingularValuesSwap) {
  const Mat3 R = Eigen::AngleAxisd(0.35, Vec3(1.0, 2.0, 0.5).normalized()).toRotationMatrix();
  for (const StrainProjection mode : kAllModes) {
    const StrainLimitParams params = CalcStrainLimitParams(
        StrainLimitSettings::PerAxis(Vec3(0.9, 0.8, 0.95), Vec3(1.2, 1.15, 1.3), mode));
    std::map<std::uint64_t, std::pair<double, int>> before;
    for (const double t : {-1e-7, 1e-7}) {
      const Tet tet = TetFromG(R * Vec3(1.1 + t, 1.1 - t, 0.9).asDiagonal() * R.transpose());
      const std::vector<StrainLimitRow> rows = AllRows(tet.r, tet.x, Mat3::Identity(), params);
      ASSERT_FALSE(rows.empty());
      if (t < 0) {
        for (const StrainLimitRow& row : rows)
          before[row.key.Pack()] = {row.C, row.principal_index};
        continue;
      }
      ASSERT_EQ(rows.size(), before.size());
      int swapped = 0;
      for (const StrainLimitRow& row : rows) {
        ASSERT_EQ(before.count(row.key.Pack()), 1u) << GetStrainProjectionName(mode);
        EXPECT_NEAR(row.C, before[row.key.Pack()].first, 1e-5);
        if (row.principal_index != before[row.key.Pack()].second) ++swapped;
      }
      EXPECT_GT(swapped, 0);  // the principal index did change
    }
  }
  const Mat3 V = (Mat3() << 0, 1, 0, 0, 0, 1, 1, 0, 0).finished();  // v_i = e_{i+2 mod 3}
  const std::array<int, 3> match = CalcPrincipalAxisMatch(V);
  EXPECT_EQ(match[0], 2);
  EXPECT_EQ(match[1], 0);
  EXPECT_EQ(match[2], 1);
}

// R2 and the margin: rows only on the side s_i - 1 points to, only with C < tau; appends.
TEST(StrainLimitRowsTest, EmitsOnlyActiveSideBelowMargin) {
  std::mt19937 rng(60);
  for (const StrainProjection mode : kAllModes) {
    StrainLimitParams params =
        CalcStrainLimitParams(Paper(StrainLimitSettings::Isotropic(0.9, 1.1, mode)));
    for (int trial = 0; trial < 50; ++trial) {
      std::array<Vec3, 4> X;
      const TetRestRows r = MakeRestRows(&rng, &X);
      const TetPositions x = PositionsFromG(RandomG(&rng), X, Vec3::Zero());
      const Mat3 Q = RandomRotation(&rng);
      const Vec3 s = CalcSignedSvd(CalcTetDeformationGradient(r, x)).s;
      const std::vector<StrainLimitRow> all = AllRows(r, x, Q, params);
      const bool per_axis =
          mode == StrainProjection::kHyperbolic || mode == StrainProjection::kOrthogonal;
      EXPECT_EQ(all.size(), per_axis ? 9u : 3u);
      double min_C = kInf;
      for (const StrainLimitRow& row : all) {
        EXPECT_EQ(row.key.bound == StrainBound::kMax, s[row.principal_index] > 1.0);
        EXPECT_EQ(row.key.element, 3);
        min_C = std::min(min_C, row.C);
      }
      EXPECT_EQ(CalcStrainLimitViolation(r, x, Q, params), std::max(0.0, -min_C));
      params.activation_margin = 0.5;
      std::vector<StrainLimitRow> rows(2);  // appended after existing entries
      const int n = AppendStrainLimitRows(3, r, x, Q, params, &rows);
      ASSERT_EQ(rows.size(), 2u + n);
      int expected = 0;
      for (const StrainLimitRow& row : all) expected += row.C < 0.5;
      EXPECT_EQ(n, expected);
      for (int k = 2; k < static_cast<int>(rows.size()); ++k) EXPECT_LT(rows[k].C, 0.5);
    }
    // At rest C = 1 (OP: C = |V'_ji|, which is ~0 off the diagonal, its freezing defect), so
    // nothing is emitted for tau < 1 except OP rows, and nothing is violated.
    std::array<Vec3, 4> X;
    const TetRestRows r = MakeRestRows(&rng, &X);
    const TetPositions rest = PositionsFromG(Mat3::Identity(), X, Vec3::Ones());
    params.activation_margin = 0.99;
    std::vector<StrainLimitRow> rows;
    const int n = AppendStrainLimitRows(0, r, rest, Mat3::Identity(), params, &rows);
    if (mode != StrainProjection::kOrthogonal) {
      EXPECT_EQ(n, 0);
    }
    EXPECT_LT(CalcStrainLimitViolation(r, rest, Mat3::Identity(), params), 1e-12);
  }
}

// Material-axis strain |G q| - 1 and the frame: a stretch along Q's first axis.
TEST(StrainLimitRowsTest, MaterialAxisStrainAndFrame) {
  const Mat3 Q = Eigen::AngleAxisd(0.6, Vec3(0.2, -1.0, 0.4).normalized()).toRotationMatrix();
  const Tet tet = TetFromG(Q * Vec3(1.08, 1.0, 1.0).asDiagonal() * Q.transpose());
  EXPECT_NEAR(CalcMaterialAxisStrain(tet.r, tet.x, Q.col(0)), 0.08, 1e-12);
  EXPECT_NEAR(CalcMaterialAxisStrain(tet.r, tet.x, Q.col(1)), 0.0, 1e-12);
  const StrainLimitParams params =
      CalcStrainLimitParams(StrainLimitSettings::PerAxis(Vec3::Zero(), Vec3(1.05, 1.1, 1.1)));
  // In frame Q the 8 % stretch is on the 5 % axis: C = 1 - 0.08/0.05; in the world frame less.
  EXPECT_NEAR(CalcStrainLimitViolation(tet.r, tet.x, Q, params), 0.6, 1e-9);
  EXPECT_LT(CalcStrainLimitViolation(tet.r, tet.x, Mat3::Identity(), params), 0.6);
}

// Principal stretches of F computed independently of the rows (Eigen's JacobiSVD), signed like
// docs/math.md §0.2: the smallest is negated when det F < 0 (an inverted tet).
Vec3 IndependentPrincipalStretches(const Mat3& F) {
  Eigen::JacobiSVD<Mat3> svd(F);
  Vec3 s = svd.singularValues();
  if (F.determinant() < 0.0) s[2] = -s[2];
  return s;
}

// Paper A eqs. 9-10: Isotropic(s_min, s_max) holds iff s_min <= s_i <= s_max for every
// principal stretch, whatever the deformation's or the limit's frame; one row per principal
// stretch (and the bound it points to), C = 1 - kappa |s_i - 1|.
TEST(StrainLimitRowsTest, IsotropicMeansEveryPrincipalStretchWithinTheLimits) {
  std::mt19937 rng(70);
  std::uniform_real_distribution<double> u(0.93, 1.07), coin(0.0, 1.0);
  const double lo = 0.96, hi = 1.04;
  int feasible = 0, infeasible = 0;
  for (const StrainProjection requested :
       {StrainProjection::kEllipsoid, StrainProjection::kHyperbolic}) {
    StrainLimitSettings settings = NoFloor(StrainLimitSettings::Isotropic(lo, hi));
    settings.projection = requested;  // hyperbolic with equal limits: the same rows
    const StrainLimitParams params = CalcStrainLimitParams(settings);
    EXPECT_EQ(params.projection, StrainProjection::kEllipsoid);
    for (int trial = 0; trial < 2000; ++trial) {
      Vec3 s(u(rng), u(rng), u(rng));
      if (coin(rng) < 0.05) s[2] = -s[2];
      std::array<Vec3, 4> X;
      const TetRestRows r = MakeRestRows(&rng, &X);
      const Mat3 F = RandomRotation(&rng) * s.asDiagonal() * RandomRotation(&rng).transpose();
      const TetPositions x = PositionsFromG(F, X, Vec3(0.3, 0.1, -0.2));
      const Mat3 Q = RandomRotation(&rng);
      const Vec3 s_ref = IndependentPrincipalStretches(F);
      const bool within = (s_ref.array() >= lo).all() && (s_ref.array() <= hi).all();
      const std::vector<StrainLimitRow> rows = AllRows(r, x, Q, params);
      ASSERT_EQ(rows.size(), 3u);  // one per principal stretch (none is exactly 1)
      double min_C = kInf;
      for (const StrainLimitRow& row : rows) {
        const double s_i = s_ref[row.principal_index];
        const double kappa =
            row.key.bound == StrainBound::kMax ? 1.0 / (hi - 1.0) : 1.0 / (1.0 - lo);
        EXPECT_NEAR(row.C, 1.0 - kappa * std::abs(s_i - 1.0), 1e-9);
        min_C = std::min(min_C, row.C);
      }
      // Away from the boundary (|C| > 1e-9) the row set decides exactly like the reference.
      if (std::abs(min_C) < 1e-9) continue;
      EXPECT_EQ(min_C >= 0.0, within) << "s = " << s_ref.transpose();
      EXPECT_EQ(CalcStrainLimitViolation(r, x, Q, params) == 0.0, within);
      (within ? feasible : infeasible) += 1;
    }
  }
  std::printf("[ isotropic ] %d feasible, %d infeasible states agree with JacobiSVD\n", feasible,
              infeasible);
  EXPECT_GT(feasible, 200);
  EXPECT_GT(infeasible, 200);
  // The reported case: s_1 = 1.069 along the limit frame's diagonal satisfies paper A's
  // hyperbolic rows with equal limits (1.04 allows up to 1 + sqrt(3) 0.04 = 1.069) but not the
  // isotropic limit.
  const Vec3 diag = Vec3::Ones().normalized();
  Mat3 V;
  V.col(0) = diag;
  V.col(1) = diag.unitOrthogonal();
  V.col(2) = diag.cross(V.col(1));
  const Tet tet = TetFromG(V * Vec3(1.069, 1.0, 1.0).asDiagonal() * V.transpose());
  const StrainLimitSettings isotropic = StrainLimitSettings::Isotropic(lo, hi);
  EXPECT_NEAR(
      CalcStrainLimitViolation(tet.r, tet.x, Mat3::Identity(), CalcStrainLimitParams(isotropic)),
      0.069 / 0.04 - 1.0, 1e-9);
  EXPECT_EQ(CalcStrainLimitViolation(tet.r, tet.x, Mat3::Identity(),
                                     CalcStrainLimitParams(Paper(StrainLimitSettings::Isotropic(
                                         lo, hi, StrainProjection::kHyperbolic)))),
            0.0);
}

// Genuinely anisotropic hyperbolic limits, per (i, bound) only the dominant row and those within
// the band: every emitted row is one of the full set (same C and J), min C and the violation
// are unchanged (the dropped rows have C_j > C_min), and the row count drops.
TEST(StrainLimitRowsTest, HyperbolicBandKeepsTheFeasibleSetWithFewerRows) {
  std::mt19937 rng(80);
  std::uniform_real_distribution<double> u(0.85, 1.15);
  int full_rows = 0, kept_rows = 0, full_active = 0, kept_active = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const Vec3 s_min(0.9, 0.85, 0.95), s_max(1.1, 1.12, 1.05);
    StrainLimitSettings full = Paper(StrainLimitSettings::PerAxis(s_min, s_max));
    StrainLimitSettings banded = NoFloor(StrainLimitSettings::PerAxis(s_min, s_max));
    const StrainLimitParams p_full = CalcStrainLimitParams(full);
    const StrainLimitParams p_band = CalcStrainLimitParams(banded);
    ASSERT_EQ(p_band.projection, StrainProjection::kHyperbolic);
    std::array<Vec3, 4> X;
    const TetRestRows r = MakeRestRows(&rng, &X);
    const Mat3 F = RandomRotation(&rng) * Vec3(u(rng), u(rng), u(rng)).asDiagonal() *
                   RandomRotation(&rng).transpose();
    const TetPositions x = PositionsFromG(F, X, Vec3::Zero());
    const Mat3 Q = RandomRotation(&rng);
    const std::vector<StrainLimitRow> all = AllRows(r, x, Q, p_full);
    const std::vector<StrainLimitRow> kept = AllRows(r, x, Q, p_band);
    double min_all = kInf, min_kept = kInf;
    for (const StrainLimitRow& row : all) min_all = std::min(min_all, row.C);
    for (const StrainLimitRow& row : kept) {
      min_kept = std::min(min_kept, row.C);
      bool found = false;
      for (const StrainLimitRow& other : all) {
        if (!(other.key == row.key)) continue;
        found = true;
        EXPECT_EQ(other.C, row.C);
        EXPECT_EQ((other.J - row.J).norm(), 0.0);
      }
      EXPECT_TRUE(found);
    }
    EXPECT_EQ(min_kept, min_all);
    EXPECT_EQ(min_kept >= 0.0, min_all >= 0.0);
    EXPECT_EQ(CalcStrainLimitViolation(r, x, Q, p_band), CalcStrainLimitViolation(r, x, Q, p_full));
    full_rows += static_cast<int>(all.size());
    kept_rows += static_cast<int>(kept.size());
    // With the default margin tau = 0.2 (the rows an SQP sees).
    std::vector<StrainLimitRow> active_full, active_kept;
    AppendStrainLimitRows(0, r, x, Q, p_full, &active_full);
    AppendStrainLimitRows(0, r, x, Q, p_band, &active_kept);
    full_active += static_cast<int>(active_full.size());
    kept_active += static_cast<int>(active_kept.size());
  }
  std::printf(
      "[ hyperbolic band 0.05 ] rows (tau = inf) %d -> %d, active rows (tau = 0.2) %d -> %d\n",
      full_rows, kept_rows, full_active, kept_active);
  EXPECT_LT(kept_rows, full_rows / 2);
  EXPECT_LT(kept_active, full_active);
}

// docs/math.md §3.8: with limits on x only, the floor rows C = (s_i - s_floor) / (1 - s_floor)
// appear exactly for the principal stretches below s_floor + tau (1 - s_floor), whatever their
// direction, with C read off independently computed stretches and J matching central
// differences; an inverted element (s_3 < 0) violates its floor.
TEST(StrainLimitRowsTest, InversionFloorRowsBoundEveryPrincipalStretch) {
  std::mt19937 rng(90);
  std::uniform_real_distribution<double> u(-0.6, 1.2);
  StrainLimitSettings settings =
      StrainLimitSettings::PerAxis(Vec3(0.95, 0.0, 0.0), Vec3(1.05, kInf, kInf));
  settings.svd_gap_epsilon = 0.0;  // exact derivatives for the FD comparison
  settings.Validate(1, "test");
  const StrainLimitParams params = CalcStrainLimitParams(settings);
  const double f = params.inversion_floor;
  ASSERT_EQ(f, kDefaultInversionFloor);
  const double s_emit = f + params.activation_margin * (1.0 - f);
  int floor_rows = 0, inverted = 0, skipped_keys = 0;
  double worst = 0.0;
  for (int trial = 0; trial < 1500; ++trial) {
    const Vec3 s(u(rng), u(rng), u(rng));
    if (MinGap(s) < 0.05 || std::abs(std::abs(s.minCoeff()) - f) < 0.02) continue;
    std::array<Vec3, 4> X;
    const TetRestRows r = MakeRestRows(&rng, &X);
    const Mat3 F = RandomRotation(&rng) * s.asDiagonal() * RandomRotation(&rng).transpose();
    const TetPositions x = PositionsFromG(F, X, Vec3(0.2, -0.1, 0.4));
    const Vec3 s_ref = IndependentPrincipalStretches(F);
    std::vector<StrainLimitRow> rows;
    AppendStrainLimitRows(3, r, x, Mat3::Identity(), params, &rows);  // element 3 as AllRows
    int expected = 0;
    for (int i = 0; i < 3; ++i) expected += s_ref[i] < s_emit ? 1 : 0;
    int found = 0;
    for (const StrainLimitRow& row : rows) {
      if (row.key.axis != kStrainFloorAxis) continue;
      ++found;
      EXPECT_EQ(row.key.bound, StrainBound::kMin);
      EXPECT_NEAR(row.C, (s_ref[row.principal_index] - f) / (1.0 - f), 1e-9);
      Vec12 J_fd;
      // The key's matched axis can flip where two matches tie (R3): no FD there.
      if (!CalcFdJacobian(r, x, Mat3::Identity(), params, row.key, 1e-7, &J_fd)) {
        ++skipped_keys;
        continue;
      }
      worst = std::max(worst, (row.J - J_fd).norm() / std::max(1.0, J_fd.norm()));
    }
    EXPECT_EQ(found, expected) << "s = " << s_ref.transpose();
    floor_rows += found;
    if (s_ref[2] < 0.0) {
      ++inverted;
      EXPECT_GE(CalcStrainLimitViolation(r, x, Mat3::Identity(), params), f / (1.0 - f));
    }
  }
  std::printf("[ floor rows ] %d rows (%d keys flipped), %d inverted states, max rel J err %.2e\n",
              floor_rows, skipped_keys, inverted, worst);
  EXPECT_GT(floor_rows, 300);
  EXPECT_LT(skipped_keys, floor_rows / 20);
  EXPECT_GT(inverted, 100);
  EXPECT_LT(worst, 1e-6);
}

// A body without any limit emits no floor rows: the floor guards limited elements only.
TEST(StrainLimitRowsTest, InversionFloorNeedsALimit) {
  const Tet tet = TetFromG(Vec3(1.0, 0.5, -0.3).asDiagonal());
  StrainLimitSettings settings;  // every axis unlimited
  std::vector<StrainLimitRow> rows;
  AppendStrainLimitRows(0, tet.r, tet.x, Mat3::Identity(), CalcStrainLimitParams(settings), &rows);
  EXPECT_TRUE(rows.empty());
  settings.s_max[0] = 1.1;
  AppendStrainLimitRows(0, tet.r, tet.x, Mat3::Identity(), CalcStrainLimitParams(settings), &rows);
  EXPECT_EQ(rows.size(), 1u);  // s_3 = -0.3: its floor row only (s_1 = 1 is no stretch)
  settings.inversion_floor = 1.0;
  EXPECT_THROW(settings.Validate(1, "test"), InputError);
}

// Pack and Unpack are inverse (the curvature pass decodes the element from a row key).
TEST(StrainLimitRowsTest, KeyUnpackInvertsPack) {
  for (const int element : {0, 1, 7, 123456}) {
    for (int axis = 0; axis <= kStrainFloorAxis; ++axis) {
      for (int m = 0; m < 3; ++m) {
        for (const StrainBound bound : {StrainBound::kMin, StrainBound::kMax}) {
          const StrainLimitKey key{element, static_cast<std::int8_t>(axis),
                                   static_cast<std::int8_t>(m), bound};
          EXPECT_TRUE(StrainLimitKey::Unpack(key.Pack()) == key);
        }
      }
    }
  }
}

}  // namespace
}  // namespace taut
