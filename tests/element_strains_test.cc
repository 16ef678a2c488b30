// CalcElementStrains under a known affine deformation: principal stretches, axis strains and
// energies against values computed here from E, nu and the deformation.
#include "plugin/element_strains.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <memory>

#include "plugin/box_tet_mesher.h"
#include "plugin/hex_element_model.h"
#include "plugin/tet_element_model.h"

namespace taut {
namespace {

constexpr double kE = 2.5e5, kNu = 0.3;  // [Pa], [-]

Material MakeMaterial() { return {kE, kNu, 1000.0}; }

DeformableBodySettings MakeSettings() {
  DeformableBodySettings settings;
  settings.name = "block";
  settings.material = MakeMaterial();
  return settings;
}

// 1/2 eps:C:eps of a diagonal small strain eps = diag(e) [J/m^3], C the isotropic stiffness in
// Voigt form built from E and nu (normal block only: a diagonal strain has no shear).
double CalcStrainEnergyDensity(const Vec3& e) {
  const double c = kE / ((1 + kNu) * (1 - 2 * kNu));
  Mat3 C;
  C << 1 - kNu, kNu, kNu, kNu, 1 - kNu, kNu, kNu, kNu, 1 - kNu;
  return 0.5 * e.dot(c * C * e);
}

// Moves every node of `body` to Q D X + t (X its rest position).
void Deform(DeformableBody& body, const Mat3& Q, const Mat3& D, const Vec3& t) {
  VecX x = body.model().rest_positions();
  for (int i = 0; i < body.num_nodes(); ++i) x.segment<3>(3 * i) = Q * D * x.segment<3>(3 * i) + t;
  body.set_x(x);
}

const Mat3 kStretch = Vec3(1.1, 0.95, 1.0).asDiagonal();
const Vec3 kStrain(0.1, -0.05, 0.0);  // diag(kStretch) - 1

Mat3 MakeRotation() { return Eigen::AngleAxisd(0.8, Vec3(1, -2, 0.5).normalized()).matrix(); }

// Every element reports the stretches (1.1, 1, 0.95) (|s| descending), the axis strains
// `axis_strains` and 1/2 V eps:C:eps; the energies add up to the body's.
void ExpectAffineStretch(const DeformableBody& body, const std::vector<ElementStrain>& strains,
                         const Vec3& axis_strains) {
  ASSERT_EQ(static_cast<int>(strains.size()), body.num_elements());
  const double density = CalcStrainEnergyDensity(kStrain);
  double total = 0.0;
  for (int e = 0; e < body.num_elements(); ++e) {
    const ElementStrain& s = strains[e];
    EXPECT_NEAR(s.principal_stretches[0], 1.1, 1e-12) << "element " << e;
    EXPECT_NEAR(s.principal_stretches[1], 1.0, 1e-12) << "element " << e;
    EXPECT_NEAR(s.principal_stretches[2], 0.95, 1e-12) << "element " << e;
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(s.axis_strains[j], axis_strains[j], 1e-12);
    const double expected = density * body.element_rest_volume(e);
    EXPECT_NEAR(s.energy, expected, 1e-12 * expected) << "element " << e;
    total += s.energy;
  }
  EXPECT_NEAR(total, body.CalcElasticEnergy(), 1e-12 * total);
}

std::unique_ptr<DeformableBody> MakeTetBody() {
  return std::make_unique<DeformableBody>(
      std::make_unique<TetElementModel>(
          std::make_shared<const TetMesh>(MakeBoxTetMesh(Vec3(0.3, 0.2, 0.4), 3, 2, 2)),
          MakeMaterial()),
      MakeSettings());
}

TEST(ElementStrainsTest, TetsUnderAnAffineStretchReportItExactly) {
  const auto body = MakeTetBody();
  Deform(*body, Mat3::Identity(), kStretch, Vec3::Zero());
  ExpectAffineStretch(*body, CalcElementStrains(*body), kStrain);
}

TEST(ElementStrainsTest, RotatedAndMovedStretchReportsTheSame) {
  const auto body = MakeTetBody();
  Deform(*body, MakeRotation(), kStretch, Vec3(1, 2, -3));
  ExpectAffineStretch(*body, CalcElementStrains(*body), kStrain);
}

TEST(ElementStrainsTest, AxisStrainsFollowTheGivenAxes) {
  const auto body = MakeTetBody();
  Deform(*body, MakeRotation(), kStretch, Vec3::Zero());
  // Axes turned by 90 degrees about z: axis 0 is rest y, axis 1 is rest -x.
  const Mat3 turned = Eigen::AngleAxisd(M_PI / 2, Vec3::UnitZ()).matrix();
  ExpectAffineStretch(*body, CalcElementStrains(*body, turned), Vec3(-0.05, 0.1, 0.0));
  // One frame per element: even elements the body axes, odd ones the turned axes.
  std::vector<Mat3> frames(body->num_elements(), Mat3::Identity());
  for (size_t e = 1; e < frames.size(); e += 2) frames[e] = turned;
  const std::vector<ElementStrain> strains = CalcElementStrains(*body, frames);
  for (size_t e = 0; e < strains.size(); ++e) {
    const Vec3 expected = e % 2 ? Vec3(-0.05, 0.1, 0.0) : kStrain;
    EXPECT_NEAR((strains[e].axis_strains - expected).cwiseAbs().maxCoeff(), 0.0, 1e-12);
  }
  EXPECT_THROW(CalcElementStrains(*body, std::vector<Mat3>(3, Mat3::Identity())), InputError);
}

TEST(ElementStrainsTest, HexesUnderAnAffineStretchReportItExactly) {
  for (HexRotationMethod method :
       {HexRotationMethod::kCenterPolar, HexRotationMethod::kInscribedTet}) {
    DeformableBody body(
        std::make_unique<HexElementModel>(
            std::make_shared<const HexLattice>(MakeBoxHexLattice(Vec3(0.3, 0.2, 0.4), 3, 2, 2)),
            MakeMaterial(), method),
        MakeSettings());
    Deform(body, MakeRotation(), kStretch, Vec3(0.5, 0, 0));
    ExpectAffineStretch(body, CalcElementStrains(body), kStrain);
  }
}

TEST(ElementStrainsTest, RestBodyHasUnitStretchesAndNoEnergy) {
  const auto body = MakeTetBody();
  for (const ElementStrain& s : CalcElementStrains(*body)) {
    EXPECT_NEAR((s.principal_stretches - Vec3::Ones()).cwiseAbs().maxCoeff(), 0.0, 1e-14);
    EXPECT_NEAR(s.axis_strains.cwiseAbs().maxCoeff(), 0.0, 1e-14);
    EXPECT_NEAR(s.energy, 0.0, 1e-24);
  }
}

}  // namespace
}  // namespace taut
