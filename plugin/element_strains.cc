#include "plugin/element_strains.h"

#include "plugin/signed_svd.h"

namespace taut {
namespace {

// Stretches of F and its strains along the columns of `axes`, with the element's energy [J].
ElementStrain MakeElementStrain(const Mat3& F, const Mat3& axes, double energy) {
  ElementStrain strain;
  strain.principal_stretches = CalcSignedSvd(F).s;
  for (int j = 0; j < 3; ++j) strain.axis_strains[j] = (F * axes.col(j)).norm() - 1.0;
  strain.energy = energy;
  return strain;
}

// Every element, the axes of element e being axes[e] (num_axes == num_elements) or axes[0]: F at
// the element centre and U_e, both at the body's x.
std::vector<ElementStrain> CalcStrains(const DeformableBody& body, const Mat3* axes,
                                       std::size_t num_axes) {
  const ElementModel& model = body.model();
  std::vector<ElementStrain> strains(body.num_elements());
  for (int e = 0; e < body.num_elements(); ++e) {
    const Mat3& q = axes[num_axes == 1 ? 0 : e];
    strains[e] = MakeElementStrain(model.CalcElementDeformationGradient(e, body.x()), q,
                                   model.CalcElementEnergy(e, body.x()));
  }
  return strains;
}

}  // namespace

std::vector<ElementStrain> CalcElementStrains(const DeformableBody& body, const Mat3& axes) {
  return CalcStrains(body, &axes, 1);
}

std::vector<ElementStrain> CalcElementStrains(const DeformableBody& body,
                                              const std::vector<Mat3>& element_axes) {
  TAUT_DEMAND(element_axes.size() == static_cast<std::size_t>(body.num_elements()), "body '",
              body.name(), "': element strains need one set of axes per element (",
              body.num_elements(), "), got ", element_axes.size());
  return CalcStrains(body, element_axes.data(), element_axes.size());
}

}  // namespace taut
