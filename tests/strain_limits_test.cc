// Strain-limit settings: validation messages, kappa conversion and caps (docs/math.md §3.1).
#include "constraints/strain_limits.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <string>

namespace taut {
namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();
const double kInf = std::numeric_limits<double>::infinity();

// Runs Validate and returns the InputError message ("" when it did not throw).
std::string ValidateMessage(const StrainLimitSettings& settings, int num_elements = 4) {
  try {
    settings.Validate(num_elements, "body 'beam'");
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

// Expects an InputError whose message contains every fragment.
void ExpectError(const StrainLimitSettings& settings, std::initializer_list<const char*> parts,
                 int num_elements = 4) {
  const std::string message = ValidateMessage(settings, num_elements);
  ASSERT_FALSE(message.empty()) << "no error for " << *parts.begin();
  EXPECT_NE(message.find("body 'beam'"), std::string::npos) << message;
  for (const char* part : parts) EXPECT_NE(message.find(part), std::string::npos) << message;
}

TEST(StrainLimitsTest, FactoriesAndDefaultsAreValid) {
  EXPECT_EQ(ValidateMessage(StrainLimitSettings()), "");
  EXPECT_EQ(ValidateMessage(StrainLimitSettings::Isotropic(0.95, 1.05)), "");
  EXPECT_EQ(ValidateMessage(StrainLimitSettings::Isotropic(0.0, kUnlimitedStretch)), "");
  const StrainLimitSettings finger = StrainLimitSettings::PerAxis(
      Vec3(0.95, 0.75, 0.98), Vec3(1.05, 1.25, 1.02), StrainProjection::kEllipsoid);
  EXPECT_EQ(ValidateMessage(finger), "");
  EXPECT_EQ(finger.projection, StrainProjection::kEllipsoid);
  EXPECT_EQ(finger.s_min, Vec3(0.95, 0.75, 0.98));
  EXPECT_EQ(finger.s_max, Vec3(1.05, 1.25, 1.02));
  EXPECT_STREQ(GetStrainProjectionName(StrainProjection::kLinearInterpolation),
               "linear_interpolation");
  // Isotropic() is paper A's isotropic limit (eqs. 9-10): the ellipsoid rows.
  EXPECT_EQ(StrainLimitSettings::Isotropic(0.96, 1.04).projection, StrainProjection::kEllipsoid);
  EXPECT_TRUE(StrainLimitSettings().equal_limits_use_ellipsoid);
  EXPECT_EQ(StrainLimitSettings().hyperbolic_row_band, kDefaultHyperbolicRowBand);
}

// Hyperbolic limits equal on every limited axis (per bound) are evaluated as ellipsoid rows
// (docs/math.md §3.5: identical for one axis, isotropy-consistent for more); unequal limits, other
// modes and equal_limits_use_ellipsoid = false keep the requested rule.
TEST(StrainLimitsTest, EqualHyperbolicLimitsSelectTheEllipsoidRows) {
  const auto evaluated = [](const StrainLimitSettings& s) {
    return CalcStrainLimitParams(s).projection;
  };
  const StrainProjection kHyp = StrainProjection::kHyperbolic;
  EXPECT_EQ(evaluated(StrainLimitSettings::Isotropic(0.96, 1.04, kHyp)),
            StrainProjection::kEllipsoid);
  // The anisotropic tet beam: y and z limited alike, x free.
  EXPECT_EQ(
      evaluated(StrainLimitSettings::PerAxis(Vec3(0.0, 0.96, 0.96), Vec3(kInf, 1.04, 1.04), kHyp)),
      StrainProjection::kEllipsoid);
  // The vertical beam: one limited axis.
  EXPECT_EQ(
      evaluated(StrainLimitSettings::PerAxis(Vec3(0.95, 0.0, 0.0), Vec3(1.05, kInf, kInf), kHyp)),
      StrainProjection::kEllipsoid);
  // Different bounds per side are fine as long as each side is equal over its limited axes.
  EXPECT_EQ(evaluated(StrainLimitSettings::PerAxis(Vec3(0.9, 0.0, 0.9), Vec3(1.2, 1.2, 1.2), kHyp)),
            StrainProjection::kEllipsoid);
  EXPECT_EQ(evaluated(StrainLimitSettings::PerAxis(Vec3(0.9, 0.8, 0.9), Vec3::Constant(1.2), kHyp)),
            kHyp);
  EXPECT_EQ(evaluated(StrainLimitSettings::PerAxis(Vec3::Zero(), Vec3(1.1, 1.2, kInf), kHyp)),
            kHyp);
  StrainLimitSettings paper = StrainLimitSettings::Isotropic(0.96, 1.04, kHyp);
  paper.equal_limits_use_ellipsoid = false;
  EXPECT_EQ(evaluated(paper), kHyp);
  EXPECT_EQ(evaluated(StrainLimitSettings::Isotropic(0.96, 1.04, StrainProjection::kOrthogonal)),
            StrainProjection::kOrthogonal);
  EXPECT_EQ(
      evaluated(StrainLimitSettings::Isotropic(0.96, 1.04, StrainProjection::kLinearInterpolation)),
      StrainProjection::kLinearInterpolation);
}

TEST(StrainLimitsTest, ValidateRejectsBadLimitsNamingAxisAndRange) {
  StrainLimitSettings s = StrainLimitSettings::Isotropic(0.95, 1.05);
  s.s_min[1] = kNaN;
  ExpectError(s, {"s_min[1]", "NaN", "(0, 1)"});
  s = StrainLimitSettings::Isotropic(0.95, 1.05);
  s.s_max[2] = kNaN;
  ExpectError(s, {"s_max[2]", "NaN", "(1, +inf)"});
  s = StrainLimitSettings::PerAxis(Vec3(0.9, 1.2, 0.9), Vec3(1.1, 1.1, 1.1));
  ExpectError(s, {"axis 1", "s_min[1] = 1.2 > s_max[1] = 1.1"});
  s = StrainLimitSettings::PerAxis(Vec3(0.9, 0.9, -0.1), Vec3::Constant(1.1));
  ExpectError(s, {"s_min[2] = -0.1", "(0, 1)"});
  s = StrainLimitSettings::PerAxis(Vec3(1.0, 0.9, 0.9), Vec3::Constant(1.1));
  ExpectError(s, {"s_min[0] = 1", "(0, 1)"});
  s = StrainLimitSettings::PerAxis(Vec3::Constant(0.9), Vec3(1.1, 0.99, 1.1));
  ExpectError(s, {"s_max[1] = 0.99", "(1, +inf)"});
  s = StrainLimitSettings::PerAxis(Vec3::Constant(0.9), Vec3(1.1, 1.1, 1.0));
  ExpectError(s, {"s_max[2] = 1", "(1, +inf)"});
  // 0 is the compress convention only; a zero stretch limit is an error, not "unlimited".
  s = StrainLimitSettings::PerAxis(Vec3::Constant(0.9), Vec3(0.0, 1.1, 1.1));
  ExpectError(s, {"s_max[0] = 0", "does not mean unlimited"});
}

TEST(StrainLimitsTest, ValidateRejectsBadFramesAndOptions) {
  StrainLimitSettings s = StrainLimitSettings::Isotropic(0.95, 1.05);
  s.frame = Vec3(1.0, 1.0, -1.0).asDiagonal();  // reflection
  ExpectError(s, {"strain-limit frame", "not a rotation", "det Q = -1"});
  s.frame = 1.01 * Mat3::Identity();
  ExpectError(s, {"strain-limit frame", "not a rotation"});
  s.frame = Mat3::Identity();
  s.frame(0, 1) = kNaN;
  ExpectError(s, {"strain-limit frame", "non-finite"});

  s = StrainLimitSettings::Isotropic(0.95, 1.05);
  s.element_frames.assign(3, Mat3::Identity());
  ExpectError(s, {"3 strain-limit element frames given for 4 elements"});
  s.element_frames.assign(4, Mat3::Identity());
  EXPECT_EQ(ValidateMessage(s), "");
  s.element_frames[2] = Mat3::Zero();
  ExpectError(s, {"frame of element 2", "not a rotation"});

  s = StrainLimitSettings::Isotropic(0.95, 1.05);
  s.unlimited_s_max_cap = 1.0;
  ExpectError(s, {"unlimited_s_max_cap = 1", "> 1"});
  s.unlimited_s_max_cap = kInf;
  ExpectError(s, {"unlimited_s_max_cap = inf", "finite"});
  s = StrainLimitSettings::Isotropic(0.95, 1.05);
  s.unlimited_s_min_cap = 1.0;
  ExpectError(s, {"unlimited_s_min_cap = 1", "[0, 1)"});
  s = StrainLimitSettings::Isotropic(0.95, 1.05);
  s.activation_margin = -0.1;
  ExpectError(s, {"activation_margin = -0.1", "[0, +inf]"});
  s.activation_margin = kNaN;
  ExpectError(s, {"activation_margin = nan"});
  s.activation_margin = kInf;
  EXPECT_EQ(ValidateMessage(s), "");
  s.svd_gap_epsilon = -1e-3;
  ExpectError(s, {"svd_gap_epsilon = -0.001", ">= 0"});
  s = StrainLimitSettings::Isotropic(0.95, 1.05);
  s.hyperbolic_row_band = -0.1;
  ExpectError(s, {"hyperbolic_row_band = -0.1", "[0, +inf]"});
  s.hyperbolic_row_band = kNaN;
  ExpectError(s, {"hyperbolic_row_band = nan"});
  s.hyperbolic_row_band = kInf;
  EXPECT_EQ(ValidateMessage(s), "");
}

// docs/math.md §3.1: kappa = 1/|s - 1|, 0 for unlimited; OP / LI deviations use the caps.
TEST(StrainLimitsTest, ParamsStoreKappaAndCappedDeviations) {
  StrainLimitSettings s =
      StrainLimitSettings::PerAxis(Vec3(0.95, 0.0, 0.8), Vec3(1.05, 1.25, kUnlimitedStretch));
  s.unlimited_s_max_cap = 10.0;
  s.activation_margin = 0.3;
  s.svd_gap_epsilon = 1e-3;
  s.freeze_frame_jacobian = true;
  const StrainLimitParams p = CalcStrainLimitParams(s);
  EXPECT_NEAR(p.kappa_min[0], 20.0, 1e-12);
  EXPECT_EQ(p.kappa_min[1], 0.0);
  EXPECT_NEAR(p.kappa_min[2], 5.0, 1e-12);
  EXPECT_NEAR(p.kappa_max[0], 20.0, 1e-12);
  EXPECT_NEAR(p.kappa_max[1], 4.0, 1e-12);
  EXPECT_EQ(p.kappa_max[2], 0.0);
  EXPECT_NEAR(p.d_min_capped[0], -0.05, 1e-15);
  EXPECT_EQ(p.d_min_capped[1], -1.0);  // cap s = 0
  EXPECT_NEAR(p.d_max_capped[1], 0.25, 1e-15);
  EXPECT_EQ(p.d_max_capped[2], 9.0);  // cap s = 10
  EXPECT_TRUE(p.has_min);
  EXPECT_TRUE(p.has_max);
  EXPECT_EQ(p.activation_margin, 0.3);
  EXPECT_EQ(p.svd_gap_epsilon, 1e-3);
  EXPECT_TRUE(p.freeze_frame_jacobian);
  for (int j = 0; j < 3; ++j) {
    EXPECT_TRUE(std::isfinite(p.kappa_min[j]) && std::isfinite(p.kappa_max[j]));
  }

  const StrainLimitParams stretch_only =
      CalcStrainLimitParams(StrainLimitSettings::Isotropic(0.0, 1.1));
  EXPECT_FALSE(stretch_only.has_min);
  EXPECT_TRUE(stretch_only.has_max);
  EXPECT_EQ(stretch_only.kappa_min, Vec3::Zero());
  EXPECT_EQ(stretch_only.d_min_capped, Vec3::Constant(-1.0));
}

TEST(StrainLimitsTest, SelectFramePrefersElementFrames) {
  StrainLimitSettings s = StrainLimitSettings::Isotropic(0.95, 1.05);
  s.frame = Eigen::AngleAxisd(0.3, Vec3::UnitZ()).toRotationMatrix();
  EXPECT_EQ(SelectStrainLimitFrame(s, 7), s.frame);
  s.element_frames.assign(2, Mat3::Identity());
  s.element_frames[1] = Eigen::AngleAxisd(0.7, Vec3::UnitX()).toRotationMatrix();
  EXPECT_EQ(SelectStrainLimitFrame(s, 0), Mat3::Identity());
  EXPECT_EQ(SelectStrainLimitFrame(s, 1), s.element_frames[1]);
}

}  // namespace
}  // namespace taut
