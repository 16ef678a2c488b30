#include "demos/scenes/tet_beam_scene.h"

#include <algorithm>

#include "plugin/box_tet_mesher.h"

namespace taut {

namespace {
constexpr double kLength = 1.0;
constexpr double kWidth = 0.2;
}  // namespace

std::vector<TetBeamScene::Beam> TetBeamScene::DefaultBeams() {
  auto make = [](const std::string& name, double E, std::optional<StrainLimitSettings> limits) {
    Beam beam;
    beam.name = name;
    beam.settings = MakeSceneBodySettings(name, E, 1000.0, 1.0);
    beam.limits = limits;
    return beam;
  };
  const double free = kUnlimitedStretch;
  return {make("stiff_200kPa", 200e3, std::nullopt), make("soft_5kPa", 5e3, std::nullopt),
          make("soft_5kPa_anisotropic", 5e3,
               StrainLimitSettings::PerAxis(Vec3(0.0, 0.96, 0.96), Vec3(free, 1.04, 1.04))),
          make("soft_5kPa_isotropic", 5e3, StrainLimitSettings::Isotropic(0.96, 1.04))};
}

TetBeamScene::TetBeamScene(const std::vector<Beam>& beams, int cells_x, int cells_yz) {
  for (size_t b = 0; b < beams.size(); ++b) {
    // Beams 0.6 m apart along y so they never touch.
    const Vec3 corner(0.0, 0.6 * static_cast<double>(b), 0.0);
    auto mesh = std::make_shared<TetMesh>(
        MakeBoxTetMesh(Vec3(kLength, kWidth, kWidth), cells_x, cells_yz, cells_yz, corner));
    mesh->source = beams[b].name;
    DeformableBody* body = world().AddTetBody(mesh, beams[b].settings);
    body->FixNodesWhere([](const Vec3& X) { return X.x() < 1e-9; });
    if (beams[b].limits) world().SetStrainLimits(body, *beams[b].limits);
    std::vector<int> tip;
    for (int i = 0; i < body->num_nodes(); ++i)
      if (mesh->nodes[i].x() > kLength - 1e-9) tip.push_back(i);
    tip_nodes_.push_back(tip);
    limited_.push_back(beams[b].limits.has_value());
  }
  max_tip_.assign(beams.size(), 0.0);
}

Vec3 TetBeamScene::CalcTipDisplacement(int b) const {
  return CalcMeanDisplacement(world().deformable_body(b), tip_nodes_[b]);
}

double TetBeamScene::CalcLength(int b) const {
  // Distance from the clamped face centre to the tip centre (stretch of the beam axis).
  const DeformableBody& body = world().deformable_body(b);
  Vec3 tip = Vec3::Zero(), root = Vec3::Zero();
  for (int i : tip_nodes_[b]) tip += body.node_position(i);
  tip /= static_cast<double>(tip_nodes_[b].size());
  for (int i = 0; i < body.num_nodes(); ++i)
    if (body.node_kind(i) == NodeKind::kFixed) root += body.node_position(i);
  return (tip - root / static_cast<double>(tip_nodes_[b].size())).norm();
}

void TetBeamScene::Measure(double /*dt*/) {
  for (size_t b = 0; b < max_tip_.size(); ++b)
    max_tip_[b] = std::max(max_tip_[b], CalcTipDisplacement(static_cast<int>(b)).norm());
}

std::vector<std::string> TetBeamScene::CsvColumns() const {
  std::vector<std::string> columns;
  for (int b = 0; b < world().num_deformable_bodies(); ++b)
    columns.push_back("tip_displacement_m_" + world().deformable_body(b).name());
  return columns;
}

void TetBeamScene::AppendCsvValues(std::vector<double>& values) const {
  for (int b = 0; b < world().num_deformable_bodies(); ++b)
    values.push_back(CalcTipDisplacement(b).norm());
}

void TetBeamScene::WriteFigures(nlohmann::json& figures) const {
  for (int b = 0; b < world().num_deformable_bodies(); ++b) {
    const DeformableBody& body = world().deformable_body(b);
    const Vec3 tip = CalcTipDisplacement(b);
    nlohmann::json& entry = figures["materials"][body.name()];
    entry["youngs_modulus_pa"] = body.settings().material.youngs_modulus;
    entry["tip_displacement_m"] = tip.norm();
    entry["tip_displacement_z_m"] = tip.z();
    entry["max_tip_displacement_m"] = max_tip_[b];
    entry["num_tets"] = body.model().num_elements();
    entry["strain_limited"] = b < static_cast<int>(limited_.size()) && limited_[b];
    entry["length_m"] = CalcLength(b);
  }
}

std::vector<Scene::KeyFrame> TetBeamScene::CollectKeyFrames(int step, int num_steps) {
  const double sag = *std::max_element(max_tip_.begin(), max_tip_.end());
  return CollectPeakKeyFrames(step, num_steps, sag, &key_sag_, "largest_sag", "largest sag");
}

}  // namespace taut
