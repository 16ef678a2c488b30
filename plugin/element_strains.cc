#include "plugin/element_strains.h"

#include "plugin/hex_element_model.h"
#include "plugin/signed_svd.h"
#include "plugin/tet_element_model.h"

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

// Element e of a tet body at x.
ElementStrain CalcTetStrain(const TetElementModel& tets, const VecX& x, int e, const Mat3& axes) {
  const TetRestElement& rest = tets.rest().elements[e];
  const Mat3 F = CalcTetDeformationGradient(rest, tets.GatherElement(x, e));
  return MakeElementStrain(F, axes,
                           CalcCorotatedTetEnergy(rest, tets.lame(), F, CalcPolarRotation(F)));
}

// Element e of a hex body at x.
ElementStrain CalcHexStrain(const HexElementModel& hexes, const VecX& x, int e, const Mat3& axes) {
  const HexRestElement& rest = hexes.rest(e);
  const HexNodes xe = hexes.GatherElement(x, e);
  const Mat3 R = CalcHexRotation(rest, xe, hexes.rotation_method());
  return MakeElementStrain(CalcHexCenterDeformationGradient(rest, xe), axes,
                           CalcCorotatedHexEnergy(rest, xe, R));
}

// Every element, the axes of element e being axes[e] (num_axes == num_elements) or axes[0].
std::vector<ElementStrain> CalcStrains(const DeformableBody& body, const Mat3* axes,
                                       std::size_t num_axes) {
  const auto* tets = dynamic_cast<const TetElementModel*>(&body.model());
  const auto* hexes = dynamic_cast<const HexElementModel*>(&body.model());
  TAUT_DEMAND(tets != nullptr || hexes != nullptr, "body '", body.name(),
              "': element strains need a tet or hex body");
  std::vector<ElementStrain> strains(body.num_elements());
  for (int e = 0; e < body.num_elements(); ++e) {
    const Mat3& q = axes[num_axes == 1 ? 0 : e];
    strains[e] = tets != nullptr ? CalcTetStrain(*tets, body.x(), e, q)
                                 : CalcHexStrain(*hexes, body.x(), e, q);
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
