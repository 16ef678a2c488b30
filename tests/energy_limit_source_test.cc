#include "constraints/energy_limit_source.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "constraints/sqp_solver.h"
#include "plugin/box_tet_mesher.h"
#include "plugin/hex_element_model.h"
#include "plugin/tet_element_model.h"
#include "tests/test_utils.h"

namespace taut {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// A tet box body named "cube" (no world).
std::unique_ptr<DeformableBody> MakeCube(double youngs_modulus, int cells, double damping = 2.0) {
  DeformableBodySettings settings;
  settings.name = "cube";
  settings.material = {youngs_modulus, 0.3, 1000.0};
  settings.mass_damping = damping;
  auto mesh = std::make_shared<TetMesh>(MakeBoxTetMesh(Vec3(0.1, 0.1, 0.1), cells, cells, cells));
  return std::make_unique<DeformableBody>(
      std::make_unique<TetElementModel>(mesh, settings.material), settings);
}

// A hex box body named "hex cube" of cells^3 hexes (no world).
std::unique_ptr<DeformableBody> MakeHexCube(double youngs_modulus, int cells,
                                            double damping = 2.0) {
  DeformableBodySettings settings;
  settings.name = "hex cube";
  settings.material = {youngs_modulus, 0.3, 1000.0};
  settings.mass_damping = damping;
  auto lattice =
      std::make_shared<HexLattice>(MakeBoxHexLattice(Vec3(0.1, 0.1, 0.1), cells, cells, cells));
  return std::make_unique<DeformableBody>(
      std::make_unique<HexElementModel>(lattice, settings.material), settings);
}

const TetElementModel& Tets(const DeformableBody& body) {
  return dynamic_cast<const TetElementModel&>(body.model());
}

// Rest positions with a smooth nonuniform stretch, so element energies differ.
VecX Stretched(const DeformableBody& body, double amount) {
  VecX x = body.model().rest_positions();
  for (int i = 0; i < body.num_nodes(); ++i) {
    const double z = x[3 * i + 2];
    x[3 * i + 2] = z * (1.0 + amount * (1.0 + 10.0 * z));
    x[3 * i] += 0.3 * amount * z * z * 10.0;
  }
  return x;
}

// U_e of element e at x [J].
double ElementEnergy(const DeformableBody& body, const VecX& x, int e) {
  const TetElementModel& tets = Tets(body);
  return CalcTetElementEnergy(tets.rest().elements[e], tets.lame(), tets.GatherElement(x, e));
}

TEST(EnergyLimitSourceTest, RowsAreEmittedExactlyBelowTheMargin) {
  auto body = MakeCube(2e3, 2);
  const VecX x = Stretched(*body, 0.1);
  const int num = body->model().num_elements();
  double u_lo = kInf, u_hi = 0.0;
  for (int e = 0; e < num; ++e) {
    u_lo = std::min(u_lo, ElementEnergy(*body, x, e));
    u_hi = std::max(u_hi, ElementEnergy(*body, x, e));
  }
  ASSERT_GT(u_hi, 2.0 * u_lo);
  // U_max between the extremes: some elements violate, some are inside the margin, some not.
  const double u_max = 0.5 * (u_lo + u_hi);
  EnergyLimitSource source(*body, EnergyLimitSettings::PerElementEnergy(u_max), 5);
  std::vector<ConstraintRow> rows;
  const int appended = source.AppendRows(x, 3, rows);
  ASSERT_EQ(appended, static_cast<int>(rows.size()));
  int expected = 0;
  double max_violation = 0.0, sum = 0.0;
  for (int e = 0; e < num; ++e) {
    const double C = 1.0 - ElementEnergy(*body, x, e) / u_max;
    max_violation = std::max(max_violation, -C);
    sum += std::max(0.0, -C);
    if (C < 0.2) ++expected;
  }
  EXPECT_GT(expected, 0);
  EXPECT_LT(expected, num);
  EXPECT_EQ(appended, expected);
  for (const ConstraintRow& row : rows) {
    const int e = static_cast<int>(row.key & 0xffffffffffffULL);
    EXPECT_EQ(row.key >> 48, 5u);
    EXPECT_EQ(row.body, 3);
    EXPECT_EQ(row.type, RowType::kEnergyLimit);
    EXPECT_EQ(row.num_nodes, 4);
    EXPECT_LT(row.C, 0.2);
    EXPECT_NEAR(row.C, 1.0 - ElementEnergy(*body, x, e) / u_max, 1e-12);
    for (int n = 0; n < 4; ++n) EXPECT_EQ(row.nodes[n], Tets(*body).element_nodes(e)[n]);
  }
  EXPECT_GT(max_violation, 0.0);
  EXPECT_NEAR(source.CalcMaxViolation(x), max_violation, 1e-12);
  EXPECT_NEAR(source.CalcViolationSum(x), sum, 1e-12);
  EXPECT_NEAR(source.CalcMaxEnergyRatio(x), u_hi / u_max, 1e-12);
  // No rows and no violation at rest.
  rows.clear();
  EXPECT_EQ(source.AppendRows(body->model().rest_positions(), 0, rows), 0);
  EXPECT_EQ(source.CalcMaxViolation(body->model().rest_positions()), 0.0);
}

TEST(EnergyLimitSourceTest, RowJacobianMatchesFiniteDifferencesOfTheBodyEnergyRatio) {
  auto body = MakeCube(2e3, 1);
  const VecX x = Stretched(*body, 0.1);
  EnergyLimitSource source(*body, EnergyLimitSettings::PerElementEnergy(1e-9), 0);
  std::vector<ConstraintRow> rows;
  source.AppendRows(x, 0, rows);
  ASSERT_EQ(rows.size(), 6u);
  for (const ConstraintRow& row : rows) {
    const int e = static_cast<int>(row.key);
    VecX J = VecX::Zero(x.size());
    for (int n = 0; n < row.num_nodes; ++n) J.segment<3>(3 * row.nodes[n]) = row.J[n];
    const MatX fd = testing::CentralDifference(
        [&](const VecX& y) { return VecX::Constant(1, 1.0 - ElementEnergy(*body, y, e) / 1e-9); },
        x, 1e-7);
    ASSERT_GT(fd.norm(), 1.0);
    EXPECT_LT(testing::RelativeError(J.transpose(), fd), 1e-6) << "element " << e;
  }
}

TEST(EnergyLimitSourceTest, EnergyDensityIsMultipliedByTheRestVolume) {
  auto body = MakeCube(2e3, 2);
  const double density = 3.0;  // J/m^3
  EnergyLimitSource source(*body, EnergyLimitSettings::EnergyDensity(density), 0);
  const TetElementModel& tets = Tets(*body);
  const double cell_tet_volume = std::pow(0.05, 3) / 6.0;  // Kuhn tets: 1/6 of a 5 cm cube
  for (int e = 0; e < tets.num_elements(); ++e) {
    EXPECT_NEAR(source.element_limits()[e], density * tets.rest().elements[e].volume, 1e-18);
    EXPECT_NEAR(source.element_limits()[e], density * cell_tet_volume, 1e-15);
  }
  const VecX x = Stretched(*body, 0.1);
  std::vector<ConstraintRow> rows;
  source.AppendRows(x, 0, rows);
  ASSERT_FALSE(rows.empty());
  const int e = static_cast<int>(rows[0].key);
  EXPECT_NEAR(rows[0].C, 1.0 - ElementEnergy(*body, x, e) / (density * cell_tet_volume), 1e-12);
}

TEST(EnergyLimitSourceTest, PerElementLimitsAndUnlimitedElements) {
  auto body = MakeCube(2e3, 1);
  const VecX x = Stretched(*body, 0.1);
  EnergyLimitSettings settings;
  settings.element_u_max.assign(6, kInf);
  settings.element_u_max[2] = 1e-9;
  settings.element_u_max[4] = 1e-9;
  EnergyLimitSource source(*body, settings, 1);
  std::vector<ConstraintRow> rows;
  ASSERT_EQ(source.AppendRows(x, 0, rows), 2);
  EXPECT_EQ(rows[0].key & 0xff, 2u);
  EXPECT_EQ(rows[1].key & 0xff, 4u);
  EXPECT_NEAR(source.CalcMaxEnergyRatio(x),
              std::max(ElementEnergy(*body, x, 2), ElementEnergy(*body, x, 4)) / 1e-9, 1e-6);
}

// Expects InputError whose message contains every one of `parts`.
void ExpectInputError(const std::function<void()>& f, const std::vector<std::string>& parts) {
  try {
    f();
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& error) {
    for (const std::string& part : parts)
      EXPECT_NE(std::string(error.what()).find(part), std::string::npos)
          << "'" << part << "' missing in: " << error.what();
  }
}

TEST(EnergyLimitSourceTest, BadSettingsThrowNamingBodyElementAndRange) {
  auto body = MakeCube(2e3, 1);
  auto make = [&](const EnergyLimitSettings& s) { EnergyLimitSource source(*body, s, 0); };
  ExpectInputError([&] { make(EnergyLimitSettings()); },
                   {"body 'cube' energy limits", "u_max = 0", "(0, +inf]"});
  ExpectInputError([&] { make(EnergyLimitSettings::PerElementEnergy(-1.0)); },
                   {"cube", "u_max = -1 J", "(0, +inf]"});
  ExpectInputError([&] { make(EnergyLimitSettings::EnergyDensity(std::nan(""))); },
                   {"cube", "nan J/m^3", "(0, +inf]"});
  EnergyLimitSettings per_element;
  per_element.element_u_max.assign(5, 1.0);
  ExpectInputError([&] { make(per_element); },
                   {"cube", "5 per-element energy limits given for 6 elements"});
  per_element.element_u_max.assign(6, 1.0);
  per_element.element_u_max[3] = 0.0;
  ExpectInputError([&] { make(per_element); }, {"cube", "element 3", "(0, +inf]"});
  EnergyLimitSettings margin = EnergyLimitSettings::PerElementEnergy(1.0);
  margin.activation_margin = -0.1;
  ExpectInputError([&] { make(margin); }, {"cube", "activation_margin = -0.1", "[0, +inf]"});
  ExpectInputError(
      [&] { EnergyLimitSource(*body, EnergyLimitSettings::PerElementEnergy(1), 1 << 16); },
      {"source id"});
  EXPECT_NO_THROW(make(EnergyLimitSettings::PerElementEnergy(kInf)));
}

// The 0.1 m cube hanging from its top face with a load on its bottom nodes, stepped with the SQP
// solver (no world). Returns the final height; `max_ratio` gets the largest U_e/U_max after any
// step (measured with `limit`'s U_max even when the run is unlimited).
double RunHangingCube(bool limited, double density_limit, double* max_ratio, int* rows,
                      bool hex = false) {
  auto body = hex ? MakeHexCube(2e3, 2) : MakeCube(2e3, 2);
  body->FixNodesWhere([](const Vec3& X) { return X.z() > 0.1 - 1e-9; });
  std::vector<int> bottom;
  for (int i = 0; i < body->num_nodes(); ++i)
    if (body->model().rest_positions()[3 * i + 2] < 1e-9) bottom.push_back(i);
  EnergyLimitSource limit(*body, EnergyLimitSettings::EnergyDensity(density_limit), 0);
  std::vector<ConstraintSource*> sources;
  if (limited) sources.push_back(&limit);
  SqpSolver solver;
  const SqpSettings settings;
  const double h = 1.0 / 240.0;
  *max_ratio = 0.0;
  *rows = 0;
  for (int step = 0; step < 200; ++step) {
    for (int i : bottom) body->AddNodeForce(i, Vec3(0, 0, -2.0));
    body->BeginStep(h, Vec3(0, 0, -9.81));
    StepStats stats;
    solver.Solve(h, {body.get()}, sources, settings, stats);
    body->EndStep(h);
    *rows = std::max(*rows, stats.rows_energy);
    *max_ratio = std::max(*max_ratio, limit.CalcMaxEnergyRatio(body->x()));
  }
  double z = 0.0;
  for (int i : bottom) z += body->node_position(i).z();
  return 0.1 - z / static_cast<double>(bottom.size());
}

TEST(EnergyLimitSourceTest, HangingCubeKeepsEveryElementBelowItsEnergyLimit) {
  const double density_limit = 20.0;  // J/m^3 (about 8 % uniaxial strain at E = 2 kPa)
  double free_ratio = 0.0, limited_ratio = 0.0;
  int free_rows = 0, limited_rows = 0;
  const double free_height = RunHangingCube(false, density_limit, &free_ratio, &free_rows);
  const double limited_height = RunHangingCube(true, density_limit, &limited_ratio, &limited_rows);
  std::printf(
      "hanging cube: unlimited height %.4f m, max U/Umax %.2f; limited height %.4f m, "
      "max U/Umax %.5f, max rows %d\n",
      free_height, free_ratio, limited_height, limited_ratio, limited_rows);
  EXPECT_GT(free_ratio, 10.0);
  EXPECT_LE(limited_ratio, 1.0 + 1e-2);
  EXPECT_GT(limited_rows, 0);
  EXPECT_GT(free_height - 0.1, 3.0 * (limited_height - 0.1));
  EXPECT_GT(limited_height, 0.1);
}

const HexElementModel& Hexes(const DeformableBody& body) {
  return dynamic_cast<const HexElementModel&>(body.model());
}

TEST(EnergyLimitSourceTest, HexBodyRowsHaveEightNodesAndTheFrozenRotationJacobian) {
  auto body = MakeHexCube(2e3, 2);
  const HexElementModel& hexes = Hexes(*body);
  const VecX x = Stretched(*body, 0.1);
  const double u_max = 1e-9;
  EnergyLimitSource source(*body, EnergyLimitSettings::PerElementEnergy(u_max), 2);
  std::vector<ConstraintRow> rows;
  ASSERT_EQ(source.AppendRows(x, 1, rows), 8);
  double worst = 0.0;
  for (const ConstraintRow& row : rows) {
    const int e = static_cast<int>(row.key & 0xffffffffffffULL);
    EXPECT_EQ(row.key >> 48, 2u);
    EXPECT_EQ(row.body, 1);
    EXPECT_EQ(row.type, RowType::kEnergyLimit);
    ASSERT_EQ(row.num_nodes, 8);
    for (int n = 0; n < 8; ++n) EXPECT_EQ(row.nodes[n], hexes.element_nodes(e)[n]);
    const HexRestElement& rest = hexes.rest(e);
    const HexNodes xe = hexes.GatherElement(x, e);
    const double energy = CalcHexElementEnergy(rest, xe, HexRotationMethod::kCenterPolar);
    EXPECT_NEAR(row.C, 1.0 - energy / u_max, 1e-9 * energy / u_max);
    // FD of C over the body's positions with the element rotation frozen at x (docs/math.md §4.5).
    const Mat3 R = CalcHexRotation(rest, xe, HexRotationMethod::kCenterPolar);
    VecX J = VecX::Zero(x.size());
    for (int n = 0; n < 8; ++n) J.segment<3>(3 * row.nodes[n]) = row.J[n];
    const MatX fd = testing::CentralDifference(
        [&](const VecX& y) {
          const double U = CalcCorotatedHexEnergy(rest, hexes.GatherElement(y, e), R);
          return VecX::Constant(1, 1.0 - U / u_max);
        },
        x, 1e-7);
    ASSERT_GT(fd.norm(), 1.0);
    worst = std::max(worst, testing::RelativeError(J.transpose(), fd));
  }
  EXPECT_LT(worst, 1e-6);
  double min_C = kInf;
  for (const ConstraintRow& row : rows) min_C = std::min(min_C, row.C);
  EXPECT_NEAR(source.CalcMaxEnergyRatio(x), 1.0 - min_C, 1e-9 * (1.0 - min_C));
  // Energy densities are multiplied by the hex rest volume (5 cm cubes).
  EnergyLimitSource density(*body, EnergyLimitSettings::EnergyDensity(3.0), 0);
  for (double limit : density.element_limits()) EXPECT_NEAR(limit, 3.0 * std::pow(0.05, 3), 1e-15);
}

TEST(EnergyLimitSourceTest, RowCurvatureAlongItsJacobianIsTheFrozenRotationCurvature) {
  // curvature_along_j = J^T (-d^2C/dx^2) J with the rotation frozen at x (the curvature of
  // AddIslandCurvature, K_e / U_max). Tets: against CalcTetEnergyLimitCurvature (finite-difference
  // tested in energy_limit_rows_test.cc). Hexes: -d^2/dt^2 C(x + t J) by central differences of
  // the frozen-rotation energy (quadratic in t, so exact up to round-off).
  const double u_max = 1e-9;
  auto tet_body = MakeCube(2e3, 1);
  auto hex_body = MakeHexCube(2e3, 2);
  for (const DeformableBody* body : {tet_body.get(), hex_body.get()}) {
    const VecX x = Stretched(*body, 0.1);
    EnergyLimitSource source(*body, EnergyLimitSettings::PerElementEnergy(u_max), 0);
    std::vector<ConstraintRow> rows;
    ASSERT_GT(source.AppendRows(x, 0, rows), 0);
    for (const ConstraintRow& row : rows) {
      const int e = static_cast<int>(row.key & 0xffffffffffffULL);
      VecX J_element(3 * row.num_nodes), J = VecX::Zero(x.size());
      for (int n = 0; n < row.num_nodes; ++n) {
        J_element.segment<3>(3 * n) = row.J[n];
        J.segment<3>(3 * row.nodes[n]) = row.J[n];
      }
      double expected = 0.0;
      if (body == tet_body.get()) {
        const TetElementModel& tets = Tets(*body);
        const Mat12 H = CalcTetEnergyLimitCurvature(tets.rest().elements[e], tets.lame(),
                                                    tets.GatherElement(x, e), u_max);
        expected = J_element.dot(H * J_element);
      } else {
        const HexElementModel& hexes = Hexes(*body);
        const HexRestElement& rest = hexes.rest(e);
        const Mat3 R =
            CalcHexRotation(rest, hexes.GatherElement(x, e), HexRotationMethod::kCenterPolar);
        const auto C = [&](double t) {
          return 1.0 - CalcCorotatedHexEnergy(rest, hexes.GatherElement(x + t * J, e), R) / u_max;
        };
        const double t = 1e-3 / J.norm();
        expected = -(C(t) - 2.0 * C(0.0) + C(-t)) / (t * t);
      }
      ASSERT_GT(expected, 0.0);
      EXPECT_NEAR(row.curvature_along_j, expected, 1e-6 * expected)
          << body->name() << " element " << e;
    }
  }
}

TEST(EnergyLimitSourceTest, HangingHexCubeKeepsEveryElementBelowItsEnergyLimit) {
  const double density_limit = 20.0;  // J/m^3
  double free_ratio = 0.0, limited_ratio = 0.0;
  int free_rows = 0, limited_rows = 0;
  const double free_height =
      RunHangingCube(false, density_limit, &free_ratio, &free_rows, /*hex=*/true);
  const double limited_height =
      RunHangingCube(true, density_limit, &limited_ratio, &limited_rows, /*hex=*/true);
  std::printf(
      "hanging hex cube: unlimited height %.4f m, max U/Umax %.2f; limited height %.4f m, "
      "max U/Umax %.5f, max rows %d\n",
      free_height, free_ratio, limited_height, limited_ratio, limited_rows);
  EXPECT_GT(free_ratio, 10.0);
  EXPECT_LE(limited_ratio, 1.0 + 1e-2);
  EXPECT_GT(limited_rows, 0);
  EXPECT_GT(free_height - 0.1, 3.0 * (limited_height - 0.1));
  EXPECT_GT(limited_height, 0.1);
}

}  // namespace
}  // namespace taut
