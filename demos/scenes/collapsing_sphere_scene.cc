#include "demos/scenes/collapsing_sphere_scene.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "plugin/hex_shapes.h"

namespace taut {

namespace {
constexpr double kRadius = 1.0;        // [m]
constexpr double kDensity = 500.0;     // [kg/m^3]
constexpr double kSpacing = 3.0;       // sphere centres apart along x [m]
constexpr int kMeterSourceId = 65535;  // energy meters never enter the world
}  // namespace

std::vector<CollapsingSphereScene::Sphere> CollapsingSphereScene::DefaultSpheres() {
  return {{"soft_50kPa", 50e3, std::nullopt}, {"limited_50kPa_50J", 50e3, 50.0}};
}

CollapsingSphereScene::CollapsingSphereScene(const std::vector<Sphere>& spheres, double cell_size,
                                             double drop_height) {
  TAUT_DEMAND(std::isfinite(drop_height) && drop_height >= 0.0,
              "collapsing sphere scene: drop height ", drop_height, " must be finite and >= 0");
  holder_.AddStaticGround();
  for (size_t s = 0; s < spheres.size(); ++s) {
    const Vec3 centre(kSpacing * static_cast<double>(s), 0.0, drop_height + kRadius);
    auto lattice = std::make_shared<HexLattice>(MakeSphereHexLattice(kRadius, cell_size, centre));
    lattice->source = spheres[s].name;
    DeformableBodySettings settings =
        MakeSceneBodySettings(spheres[s].name, spheres[s].youngs_modulus, kDensity);
    settings.contact_margin = 0.05;
    DeformableBody* body = world().AddHexBody(lattice, settings);
    limits_.push_back(spheres[s].u_max
                          ? world().SetEnergyLimits(
                                body, EnergyLimitSettings::PerElementEnergy(*spheres[s].u_max))
                          : nullptr);
    // U_e/U_max of every sphere, against its own limit or the paper's 50 J.
    meters_.push_back(std::make_unique<EnergyLimitSource>(
        *body, EnergyLimitSettings::PerElementEnergy(spheres[s].u_max.value_or(kMeterEnergy)),
        kMeterSourceId));
    double lo, hi;
    CalcZRange(static_cast<int>(s), lo, hi);
    rest_extent_.push_back(hi - lo);
  }
  max_flattening_.assign(spheres.size(), 0.0);
  max_ratio_.assign(spheres.size(), 0.0);
  min_volume_ratio_.assign(spheres.size(), 1.0);
  deepest_.assign(spheres.size(), 0.0);
}

void CollapsingSphereScene::CalcZRange(int s, double& lo, double& hi) const {
  const DeformableBody& body = world().deformable_body(s);
  lo = HUGE_VAL;
  hi = -HUGE_VAL;
  for (int i = 0; i < body.num_nodes(); ++i) {
    lo = std::min(lo, body.node_position(i).z());
    hi = std::max(hi, body.node_position(i).z());
  }
}

double CollapsingSphereScene::CalcFlattening(int s) const {
  double lo, hi;
  CalcZRange(s, lo, hi);
  return 1.0 - (hi - lo) / rest_extent_[s];
}

double CollapsingSphereScene::CalcTop(int s) const {
  double lo, hi;
  CalcZRange(s, lo, hi);
  return hi;
}

double CollapsingSphereScene::CalcMinVolumeRatio(int s) const {
  const DeformableBody& body = world().deformable_body(s);
  const HexLattice* lattice = body.rest_hex_lattice();
  TAUT_DEMAND(lattice != nullptr, "collapsing sphere scene: body '", body.name(),
              "' is not a hex body");
  double ratio = HUGE_VAL;
  for (const auto& hex : lattice->hexes) {
    std::array<Vec3, 8> x, X;
    for (int a = 0; a < 8; ++a) {
      x[a] = body.node_position(hex[a]);
      X[a] = lattice->nodes[hex[a]];
    }
    // J = det(dx/ds) / det(dX/ds) at each Gauss point.
    for (int q = 0; q < 8; ++q) {
      const Vec3 gauss = HexGaussPoint(q);
      ratio = std::min(
          ratio, CalcHexJacobian(x, gauss).determinant() / CalcHexJacobian(X, gauss).determinant());
    }
  }
  return ratio;
}

void CollapsingSphereScene::Measure(double /*dt*/) {
  ++steps_;
  ms_sum_ += world().last_step_stats().ms_total;
  for (int s = 0; s < num_spheres(); ++s) {
    double lo, hi;
    CalcZRange(s, lo, hi);
    deepest_[s] = std::min(deepest_[s], lo);
    max_flattening_[s] = std::max(max_flattening_[s], 1.0 - (hi - lo) / rest_extent_[s]);
    max_ratio_[s] =
        std::max(max_ratio_[s], meters_[s]->CalcMaxEnergyRatio(world().deformable_body(s).x()));
    min_volume_ratio_[s] = std::min(min_volume_ratio_[s], CalcMinVolumeRatio(s));
  }
}

std::vector<std::string> CollapsingSphereScene::CsvColumns() const {
  std::vector<std::string> columns;
  for (int s = 0; s < num_spheres(); ++s) {
    const std::string& name = world().deformable_body(s).name();
    for (const char* column : {"bottom_z_m_", "top_z_m_", "energy_ratio_", "min_volume_ratio_"})
      columns.push_back(column + name);
  }
  return columns;
}

void CollapsingSphereScene::AppendCsvValues(std::vector<double>& values) const {
  for (int s = 0; s < num_spheres(); ++s) {
    double lo, hi;
    CalcZRange(s, lo, hi);
    values.push_back(lo);
    values.push_back(hi);
    values.push_back(meters_[s]->CalcMaxEnergyRatio(world().deformable_body(s).x()));
    values.push_back(CalcMinVolumeRatio(s));
  }
}

void CollapsingSphereScene::WriteFigures(nlohmann::json& figures) const {
  for (int s = 0; s < num_spheres(); ++s) {
    const DeformableBody& body = world().deformable_body(s);
    nlohmann::json& entry = figures["materials"][body.name()];
    entry["num_hexes"] = body.model().num_elements();
    entry["u_max_J"] = limited(s) ? nlohmann::json(meters_[s]->element_limits()[0]) : nullptr;
    entry["max_flattening"] = max_flattening_[s];
    entry["final_flattening"] = CalcFlattening(s);
    entry["final_top_m"] = CalcTop(s);
    entry["max_energy_ratio"] = max_ratio_[s];  // unlimited spheres: against 50 J
    entry["min_volume_ratio"] = min_volume_ratio_[s];
    entry["deepest_penetration_m"] = -deepest_[s];
  }
  figures["mean_ms_step"] = mean_ms_step();
}

std::vector<Scene::KeyFrame> CollapsingSphereScene::CollectKeyFrames(int step, int num_steps) {
  const double flattening = *std::max_element(max_flattening_.begin(), max_flattening_.end());
  return CollectPeakKeyFrames(step, num_steps, flattening, &key_flattening_, "impact",
                              "impact (largest flattening)", "rest");
}

}  // namespace taut
