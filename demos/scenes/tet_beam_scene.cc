#include "demos/scenes/tet_beam_scene.h"

#include "plugin/box_tet_mesher.h"

namespace taut {

namespace {
constexpr double kLength = 1.0;
constexpr double kWidth = 0.2;
}  // namespace

std::vector<TetBeamScene::Beam> TetBeamScene::DefaultBeams() {
  std::vector<Beam> beams;
  for (double E : {200e3, 5e3}) {
    Beam beam;
    beam.name = E > 1e4 ? "stiff_200kPa" : "soft_5kPa";
    beam.settings.name = beam.name;
    beam.settings.material = {E, 0.3, 1000.0};
    beam.settings.mass_damping = 1.0;
    beams.push_back(beam);
  }
  return beams;
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
    std::vector<int> tip;
    for (int i = 0; i < body->num_nodes(); ++i)
      if (mesh->nodes[i].x() > kLength - 1e-9) tip.push_back(i);
    tip_nodes_.push_back(tip);
  }
  max_tip_.assign(beams.size(), 0.0);
}

Vec3 TetBeamScene::CalcTipDisplacement(int b) const {
  const DeformableBody& body = world().deformable_body(b);
  Vec3 sum = Vec3::Zero();
  for (int i : tip_nodes_[b])
    sum += body.node_position(i) - body.model().rest_positions().segment<3>(3 * i);
  return sum / static_cast<double>(tip_nodes_[b].size());
}

void TetBeamScene::Step(double dt) {
  Scene::Step(dt);
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
  }
}

}  // namespace taut
