#include "plugin/tet_element_model.h"

namespace taut {

template class ElementModelImpl<TetElementTraits>;

namespace {
// *mesh, after checking there is one.
const TetMesh& DemandMesh(const std::shared_ptr<const TetMesh>& mesh) {
  TAUT_DEMAND(mesh != nullptr, "TetElementModel: mesh is null");
  return *mesh;
}
}  // namespace

TetElementModel::TetElementModel(std::shared_ptr<const TetMesh> mesh, const Material& material)
    : ElementModelImpl(mesh, TetElementTraits::CalcRestData(DemandMesh(mesh), material)) {}

}  // namespace taut
