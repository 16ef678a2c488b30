// Per-element strain figures of a deformable body at its current positions, on request (reports,
// colouring, checking limits by hand). Nothing here is used by the step.
#pragma once

#include <vector>

#include "plugin/deformable_body.h"

namespace taut {

// Strain of one element at the body's current positions x.
struct ElementStrain {
  // Signed singular values of the deformation gradient F (plugin/signed_svd.h): sorted by |s|
  // descending, s[2] < 0 for an inverted element [-]; 1 at rest, 1.1 stretched by 10 %.
  Vec3 principal_stretches = Vec3::Ones();
  // |F q_j| - 1 along limit axis j, q_j the unit column j of the axes given in rest coordinates
  // (as StrainLimitSource::CalcMaxAxisStrain) [-]; 0 at rest.
  Vec3 axis_strains = Vec3::Zero();
  // Co-rotational elastic energy of the element [J], what energy limits bound (U_e <= U_max,e).
  double energy = 0.0;
};

// The strain of every element of a body at its current positions x: F =
// ElementModel::CalcElementDeformationGradient (tets: F of the linear tet; hexes: G(0) at the
// element centre, exact for an affine deformation) and U_e = ElementModel::CalcElementEnergy.
// `axes`: limit axes as columns (e.g. StrainLimitSettings::frame).
std::vector<ElementStrain> CalcElementStrains(const DeformableBody& body,
                                              const Mat3& axes = Mat3::Identity());

// The same with one set of axes per element (e.g. StrainLimitSettings::element_frames); throws
// InputError unless there is one per element.
std::vector<ElementStrain> CalcElementStrains(const DeformableBody& body,
                                              const std::vector<Mat3>& element_axes);

}  // namespace taut
