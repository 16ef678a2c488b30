#include "demos/scenes/scene.h"

#include <cstring>

#include "plugin/vtk_hex_writer.h"
#include "plugin/vtk_writer.h"

namespace taut {

void Scene::Step(double dt) {
  Simulate(dt);
  Measure(dt);
}

void Scene::Simulate(double dt) { world().stepSimulation(dt, 1, dt); }

void Scene::WriteVtkFrame(const std::string& dir, int frame, double time) const {
  if (time < 0.0) time = frame;
  for (int b = 0; b < num_deformable_bodies(); ++b) {
    const DeformableBody& body = deformable_body(b);
    const TetMesh* mesh = body.rest_tet_mesh();
    const HexLattice* lattice = body.rest_hex_lattice();
    if (mesh == nullptr && lattice == nullptr) continue;
    std::vector<Vec3> positions(body.num_nodes());
    for (int i = 0; i < body.num_nodes(); ++i) positions[i] = body.node_position(i);
    char name[64];
    std::snprintf(name, sizeof(name), "_%06d.vtk", frame);
    if (mesh != nullptr) {
      WriteVtkMesh(dir + "/" + body.name() + name, *mesh, &positions);
    } else {
      WriteVtkHexLattice(dir + "/" + body.name() + name, *lattice, &positions);
    }
    vtk_series_.Add(dir, body.name(), body.name() + name, time);
  }
  for (int i = 0; i < num_embedded_surfaces(); ++i) {
    const std::vector<Vec3> positions = CalcEmbeddedSurfacePositions(i);
    char name[64];
    std::snprintf(name, sizeof(name), "_surface_%06d", frame);
    const std::string base = dir + "/" + deformable_body(embedded_[i].body).name() + name;
    WriteVtkSurface(base + ".vtk", positions, embedded_[i].surface.triangles);
    WriteEmbeddedSurfaceObj(base + ".obj", positions, embedded_[i].surface.triangles);
    const std::string& body_name = deformable_body(embedded_[i].body).name();
    vtk_series_.Add(dir, body_name + "_surface", body_name + name + ".vtk", time);
  }
}

std::vector<Scene::KeyFrame> Scene::CollectKeyFrames(int step, int num_steps) {
  std::vector<KeyFrame> frames;
  if (step == 0) frames.push_back({"start", "start"});
  if (step == num_steps / 2 && step > 0 && step < num_steps)
    frames.push_back({"middle", "step " + std::to_string(step)});
  if (step == num_steps && step > 0) frames.push_back({"end", "end, step " + std::to_string(step)});
  return frames;
}

std::vector<Scene::KeyFrame> CollectPeakKeyFrames(int step, int num_steps, double value,
                                                  double* peak, const std::string& slot,
                                                  const std::string& caption,
                                                  const std::string& end_caption) {
  std::vector<Scene::KeyFrame> frames;
  if (step == 0) frames.push_back({"start", "start"});
  // Grown by more than rounding: a quantity that stays flat keeps its first peak frame.
  const bool grew = step > 0 && value > *peak * (1.0 + 1e-9) + 1e-12;
  if (grew) *peak = value;
  if (grew && step == num_steps) {
    // Still growing at the end (e.g. a shortened run): one frame, replacing the earlier peak.
    frames.push_back({slot, caption + ", end"});
  } else if (grew) {
    frames.push_back({slot, caption});  // replaces the frame of the previous peak
  } else if (step == num_steps && step > 0) {
    frames.push_back({"end", end_caption});
  }
  return frames;
}

int Scene::AttachEmbeddedSurface(int body, const SurfaceMesh& surface) {
  const ElementModel& model = deformable_body(body).model();
  embedded_.push_back({body, MakeEmbeddedBodyContactSurface(model, surface)});
  return static_cast<int>(embedded_.size()) - 1;
}

std::vector<Vec3> Scene::CalcEmbeddedSurfacePositions(int i) const {
  const EmbeddedSurfaceOutput& out = embedded_[i];
  return CalcContactPointPositions(out.surface, deformable_body(out.body).x());
}

namespace {
// FNV-1a over raw bytes.
void HashBytes(uint64_t& hash, const void* data, size_t size) {
  const auto* bytes = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < size; ++i) {
    hash ^= bytes[i];
    hash *= 1099511628211ull;
  }
}
}  // namespace

uint64_t Scene::CalcStateHash() const {
  uint64_t hash = 14695981039346656037ull;
  for (int b = 0; b < num_deformable_bodies(); ++b) {
    const DeformableBody& body = deformable_body(b);
    HashBytes(hash, body.x().data(), sizeof(double) * body.x().size());
    HashBytes(hash, body.v().data(), sizeof(double) * body.v().size());
  }
  const btCollisionObjectArray& objects = collision_objects();
  for (int i = 0; i < objects.size(); ++i) {
    const btRigidBody* rigid = btRigidBody::upcast(objects[i]);
    if (rigid == nullptr) continue;
    const btTransform& t = rigid->getWorldTransform();
    double pose[12];
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) pose[3 * r + c] = t.getBasis()[r][c];
      pose[9 + r] = t.getOrigin()[r];
    }
    HashBytes(hash, pose, sizeof(pose));
    const btVector3 lin = rigid->getLinearVelocity(), ang = rigid->getAngularVelocity();
    const double vel[6] = {lin.x(), lin.y(), lin.z(), ang.x(), ang.y(), ang.z()};
    HashBytes(hash, vel, sizeof(vel));
  }
  return hash;
}

DeformableBodySettings MakeSceneBodySettings(const std::string& name, double youngs_modulus,
                                             double density, double mass_damping) {
  DeformableBodySettings settings;
  settings.name = name;
  settings.material = {youngs_modulus, 0.3, density};
  settings.mass_damping = mass_damping;
  return settings;
}

Vec3 CalcMeanDisplacement(const DeformableBody& body, const std::vector<int>& nodes) {
  Vec3 sum = Vec3::Zero();
  for (int i : nodes)
    sum += body.node_position(i) - body.model().rest_positions().segment<3>(3 * i);
  return sum / static_cast<double>(nodes.size());
}

const SceneInfo& FindScene(const std::string& name) {
  std::string known;
  for (const SceneInfo& info : SceneRegistry()) {
    if (info.name == name) return info;
    known += (known.empty() ? "" : ", ") + info.name;
  }
  throw InputError("unknown scene '" + name + "'; known scenes: " + known);
}

}  // namespace taut
