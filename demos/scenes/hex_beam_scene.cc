#include "demos/scenes/hex_beam_scene.h"

#include <algorithm>

#include "plugin/hex_shapes.h"

namespace taut {

namespace {
constexpr double kLength = 1.0;
constexpr double kRadius = 0.06;
}  // namespace

std::vector<HexBeamScene::Beam> HexBeamScene::DefaultBeams() {
  auto make = [](const std::string& name, double E, std::optional<double> u_max) {
    Beam beam;
    beam.name = name;
    beam.settings = MakeSceneBodySettings(name, E, 500.0, 2.0);
    beam.u_max = u_max;
    return beam;
  };
  return {make("linear_150kPa", 150e3, std::nullopt), make("limited_1.0J", 150e3, 1.0),
          make("limited_0.5J", 150e3, 0.5), make("limited_0.1J", 150e3, 0.1),
          make("stiff_2MPa", 2e6, std::nullopt)};
}

HexBeamScene::HexBeamScene(const std::vector<Beam>& beams, double cell_size) {
  for (size_t b = 0; b < beams.size(); ++b) {
    // Beams 0.5 m apart along y so they never touch.
    auto lattice = std::make_shared<HexLattice>(MakeCylinderHexLattice(
        kLength, kRadius, cell_size, Vec3(0.0, 0.5 * static_cast<double>(b), 0.0)));
    lattice->source = beams[b].name;
    DeformableBody* body = world().AddHexBody(lattice, beams[b].settings);
    body->FixNodesWhere([](const Vec3& X) { return X.x() < 1e-9; });
    EnergyLimitSource* limits = nullptr;
    if (beams[b].u_max)
      limits =
          world().SetEnergyLimits(body, EnergyLimitSettings::PerElementEnergy(*beams[b].u_max));
    limits_.push_back(limits);
    std::vector<int> tip;
    for (int i = 0; i < body->num_nodes(); ++i)
      if (lattice->nodes[i].x() > kLength - 1e-9) tip.push_back(i);
    tip_nodes_.push_back(tip);
    // The visible round beam (12 cm diameter), embedded in the voxel lattice.
    AttachEmbeddedSurface(static_cast<int>(b),
                          MakeCylinderSurface(kLength, kRadius, 24, 14,
                                              Vec3(0.0, 0.5 * static_cast<double>(b), 0.0)));
  }
  max_ratio_.assign(beams.size(), 0.0);
  max_energy_.assign(beams.size(), 0.0);
  max_tip_.assign(beams.size(), 0.0);
}

Vec3 HexBeamScene::CalcTipDisplacement(int b) const {
  return CalcMeanDisplacement(world().deformable_body(b), tip_nodes_[b]);
}

double HexBeamScene::CalcMaxElementEnergy(int b) const {
  const DeformableBody& body = world().deformable_body(b);
  double energy = 0.0;
  for (int e = 0; e < body.num_elements(); ++e)
    energy = std::max(energy, body.model().CalcElementEnergy(e, body.x()));
  return energy;
}

double HexBeamScene::CalcMaxEnergyRatio(int b) const {
  if (limits_[b] == nullptr) return 0.0;
  return limits_[b]->CalcMaxEnergyRatio(world().deformable_body(b).x());
}

void HexBeamScene::Measure(double /*dt*/) {
  for (size_t b = 0; b < limits_.size(); ++b) {
    max_ratio_[b] = std::max(max_ratio_[b], CalcMaxEnergyRatio(static_cast<int>(b)));
    max_energy_[b] = std::max(max_energy_[b], CalcMaxElementEnergy(static_cast<int>(b)));
    max_tip_[b] = std::max(max_tip_[b], CalcTipDisplacement(static_cast<int>(b)).norm());
  }
}

std::vector<std::string> HexBeamScene::CsvColumns() const {
  std::vector<std::string> columns;
  for (int b = 0; b < world().num_deformable_bodies(); ++b) {
    columns.push_back("tip_displacement_m_" + world().deformable_body(b).name());
    columns.push_back("max_element_energy_j_" + world().deformable_body(b).name());
  }
  return columns;
}

void HexBeamScene::AppendCsvValues(std::vector<double>& values) const {
  for (int b = 0; b < world().num_deformable_bodies(); ++b) {
    values.push_back(CalcTipDisplacement(b).norm());
    values.push_back(CalcMaxElementEnergy(b));
  }
}

void HexBeamScene::WriteFigures(nlohmann::json& figures) const {
  for (int b = 0; b < world().num_deformable_bodies(); ++b) {
    const DeformableBody& body = world().deformable_body(b);
    const Vec3 tip = CalcTipDisplacement(b);
    nlohmann::json& entry = figures["materials"][body.name()];
    entry["youngs_modulus_pa"] = body.settings().material.youngs_modulus;
    entry["tip_displacement_m"] = tip.norm();
    entry["tip_displacement_z_m"] = tip.z();
    entry["max_tip_displacement_m"] = max_tip_[b];
    entry["num_hexes"] = body.model().num_elements();
    entry["max_element_energy_j"] = max_energy_[b];
    if (limits_[b] != nullptr) {
      entry["energy_limit_j"] = limits_[b]->element_limits().front();
      entry["max_energy_ratio"] = max_ratio_[b];
    } else {
      entry["energy_limit_j"] = nullptr;
      entry["max_energy_ratio"] = nullptr;
    }
  }
}

std::vector<Scene::KeyFrame> HexBeamScene::CollectKeyFrames(int step, int num_steps) {
  const double sag = *std::max_element(max_tip_.begin(), max_tip_.end());
  return CollectPeakKeyFrames(step, num_steps, sag, &key_sag_, "largest_sag", "largest sag");
}

}  // namespace taut
