#include "demos/scenes/falling_sphere_scene.h"

#include <algorithm>

#include "plugin/hex_shapes.h"

namespace taut {

namespace {
constexpr double kRadius = 1.0;
constexpr double kDropHeight = 2.0;  // bottom of the sphere above the ground at t = 0 [m]
}  // namespace

std::vector<FallingSphereScene::Sphere> FallingSphereScene::DefaultSpheres() {
  return {{"soft_150kPa", 150e3, std::nullopt},
          {"stiff_1MPa", 1e6, std::nullopt},
          {"limited_150kPa_500J", 150e3, 500.0}};
}

FallingSphereScene::FallingSphereScene(const std::vector<Sphere>& spheres, double cell_size) {
  holder_.AddStaticGround();
  for (size_t s = 0; s < spheres.size(); ++s) {
    const Vec3 centre(3.0 * static_cast<double>(s), 0.0, kDropHeight + kRadius);
    auto lattice = std::make_shared<HexLattice>(MakeSphereHexLattice(kRadius, cell_size, centre));
    lattice->source = spheres[s].name;
    DeformableBodySettings settings =
        MakeSceneBodySettings(spheres[s].name, spheres[s].youngs_modulus, 500.0);
    settings.contact_margin = 0.05;
    DeformableBody* body = world().AddHexBody(lattice, settings);
    limits_.push_back(spheres[s].u_max
                          ? world().SetEnergyLimits(
                                body, EnergyLimitSettings::PerElementEnergy(*spheres[s].u_max))
                          : nullptr);
  }
  landed_.assign(spheres.size(), false);
  max_flattening_.assign(spheres.size(), 0.0);
  bounce_.assign(spheres.size(), 0.0);
  deepest_.assign(spheres.size(), 0.0);
  max_ratio_.assign(spheres.size(), 0.0);
}

double FallingSphereScene::CalcBottom(int s) const {
  const DeformableBody& body = world().deformable_body(s);
  double z = HUGE_VAL;
  for (int i = 0; i < body.num_nodes(); ++i) z = std::min(z, body.node_position(i).z());
  return z;
}

double FallingSphereScene::CalcTop(int s) const {
  const DeformableBody& body = world().deformable_body(s);
  double z = -HUGE_VAL;
  for (int i = 0; i < body.num_nodes(); ++i) z = std::max(z, body.node_position(i).z());
  return z;
}

void FallingSphereScene::Measure(double /*dt*/) {
  for (size_t s = 0; s < landed_.size(); ++s) {
    const int b = static_cast<int>(s);
    const double bottom = CalcBottom(b);
    deepest_[s] = std::min(deepest_[s], bottom);
    if (bottom < 0.01) landed_[s] = true;
    if (landed_[s]) {
      bounce_[s] = std::max(bounce_[s], bottom);
      // Flattening relative to the lattice's rest vertical extent.
      const auto& X = world().deformable_body(b).model().rest_positions();
      double lo = HUGE_VAL, hi = -HUGE_VAL;
      for (int i = 0; i < X.size() / 3; ++i) {
        lo = std::min(lo, X[3 * i + 2]);
        hi = std::max(hi, X[3 * i + 2]);
      }
      max_flattening_[s] = std::max(max_flattening_[s], 1.0 - (CalcTop(b) - bottom) / (hi - lo));
    }
    if (limits_[s] != nullptr)
      max_ratio_[s] =
          std::max(max_ratio_[s], limits_[s]->CalcMaxEnergyRatio(world().deformable_body(b).x()));
  }
}

std::vector<std::string> FallingSphereScene::CsvColumns() const {
  std::vector<std::string> columns;
  for (int s = 0; s < world().num_deformable_bodies(); ++s)
    columns.push_back("bottom_z_m_" + world().deformable_body(s).name());
  return columns;
}

void FallingSphereScene::AppendCsvValues(std::vector<double>& values) const {
  for (int s = 0; s < world().num_deformable_bodies(); ++s) values.push_back(CalcBottom(s));
}

void FallingSphereScene::WriteFigures(nlohmann::json& figures) const {
  for (int s = 0; s < world().num_deformable_bodies(); ++s) {
    nlohmann::json& entry = figures["materials"][world().deformable_body(s).name()];
    entry["num_hexes"] = world().deformable_body(s).model().num_elements();
    entry["max_flattening"] = max_flattening_[s];
    entry["bounce_height_m"] = bounce_[s];
    entry["deepest_penetration_m"] = -deepest_[s];
    entry["max_energy_ratio"] = limits_[s] != nullptr ? nlohmann::json(max_ratio_[s]) : nullptr;
  }
}

std::vector<Scene::KeyFrame> FallingSphereScene::CollectKeyFrames(int step, int num_steps) {
  const double flattening = *std::max_element(max_flattening_.begin(), max_flattening_.end());
  return CollectPeakKeyFrames(step, num_steps, flattening, &key_flattening_, "impact",
                              "impact (largest flattening)", "rest");
}

}  // namespace taut
