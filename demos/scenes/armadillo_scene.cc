#include "demos/scenes/armadillo_scene.h"

#include <algorithm>
#include <filesystem>

#include "plugin/hex_voxelizer.h"
#include "plugin/off_reader.h"

#ifndef TAUT_SOURCE_DIR
#define TAUT_SOURCE_DIR "."
#endif

namespace taut {

namespace {
constexpr double kHeight = 2.0;       // [m], the scan's y axis is up
constexpr double kCellSize = 0.1145;  // [m] -> 368 hexes (paper: ~365)
constexpr double kDrop = 0.5;         // lowest point above the ground at t = 0 [m]
// Distance between the bodies along x [m]: the scan is 1.68 m wide, and at 2 m apart the
// flattened bodies touched from t = 0.69 s on (one island of three bodies); the paper drops each
// armadillo alone.
constexpr double kSpacing = 3.5;

// Vertical extent of a body's nodes.
void CalcZRange(const DeformableBody& body, double& lo, double& hi) {
  lo = HUGE_VAL;
  hi = -HUGE_VAL;
  for (int i = 0; i < body.num_nodes(); ++i) {
    lo = std::min(lo, body.node_position(i).z());
    hi = std::max(hi, body.node_position(i).z());
  }
}
}  // namespace

std::vector<ArmadilloScene::Material> ArmadilloScene::DefaultMaterials() {
  return {{"soft_500kPa", 500e3, std::nullopt},
          {"stiff_5MPa", 5e6, std::nullopt},
          {"limited_500kPa_100J", 500e3, 100.0}};
}

ArmadilloScene::ArmadilloScene(const std::vector<Material>& materials,
                               const std::string& off_path) {
  const std::string path =
      off_path.empty() ? std::string(TAUT_SOURCE_DIR) + "/data/armadillo.off" : off_path;
  TAUT_DEMAND(std::filesystem::exists(path), "armadillo scene: ", path,
              " is missing; run scripts/fetch_armadillo.sh");
  SurfaceMesh scan = ReadOffSurface(path);
  // Scale to 2 m tall, y up in the scan -> z up in the world: (x, y, z) -> (x, z, y) is a
  // reflection, so use (x, -z, y), a rotation.
  const Eigen::AlignedBox3d bounds = CalcSurfaceBounds(scan);
  const double scale = kHeight / bounds.sizes().y();
  for (Vec3& v : scan.vertices) {
    const Vec3 u = (v - bounds.min()) * scale;
    v = Vec3(u.x(), -u.z(), u.y() + kDrop);
  }
  holder_.AddStaticGround();
  for (size_t m = 0; m < materials.size(); ++m) {
    SurfaceMesh placed = scan;
    for (Vec3& v : placed.vertices) v.x() += kSpacing * static_cast<double>(m);
    placed.source = materials[m].name;
    auto lattice = std::make_shared<HexLattice>(VoxelizeSurface(placed, kCellSize));
    DeformableBodySettings settings =
        MakeSceneBodySettings(materials[m].name, materials[m].youngs_modulus, 500.0);
    settings.contact_margin = 0.05;
    DeformableBody* body = world().AddHexBody(lattice, settings);
    limits_.push_back(materials[m].u_max
                          ? world().SetEnergyLimits(
                                body, EnergyLimitSettings::PerElementEnergy(*materials[m].u_max))
                          : nullptr);
    AttachEmbeddedSurface(static_cast<int>(m), placed);
    double lo, hi;
    CalcZRange(*body, lo, hi);
    rest_height_.push_back(hi - lo);
  }
  max_flattening_.assign(materials.size(), 0.0);
  deepest_.assign(materials.size(), 0.0);
  max_ratio_.assign(materials.size(), 0.0);
}

void ArmadilloScene::Measure(double /*dt*/) {
  for (size_t m = 0; m < max_flattening_.size(); ++m) {
    const DeformableBody& body = world().deformable_body(static_cast<int>(m));
    double lo, hi;
    CalcZRange(body, lo, hi);
    deepest_[m] = std::min(deepest_[m], lo);
    max_flattening_[m] = std::max(max_flattening_[m], 1.0 - (hi - lo) / rest_height_[m]);
    if (limits_[m] != nullptr)
      max_ratio_[m] = std::max(max_ratio_[m], limits_[m]->CalcMaxEnergyRatio(body.x()));
  }
}

void ArmadilloScene::WriteFigures(nlohmann::json& figures) const {
  for (size_t m = 0; m < max_flattening_.size(); ++m) {
    const DeformableBody& body = world().deformable_body(static_cast<int>(m));
    nlohmann::json& entry = figures["materials"][body.name()];
    entry["num_hexes"] = body.model().num_elements();
    entry["max_flattening"] = max_flattening_[m];
    entry["deepest_penetration_m"] = -deepest_[m];
    entry["max_energy_ratio"] = limits_[m] != nullptr ? nlohmann::json(max_ratio_[m]) : nullptr;
  }
  figures["credit"] = "Stanford 3D Scanning Repository (via Debian libcgal-demo)";
}

std::vector<Scene::KeyFrame> ArmadilloScene::CollectKeyFrames(int step, int num_steps) {
  const double flattening = *std::max_element(max_flattening_.begin(), max_flattening_.end());
  return CollectPeakKeyFrames(step, num_steps, flattening, &key_flattening_, "impact",
                              "impact (largest flattening)", "rest");
}

}  // namespace taut
