#include "plugin/signed_svd.h"

#include <Eigen/LU>
#include <Eigen/SVD>

namespace taut {

SignedSvd CalcSignedSvd(const Mat3& G) {
  // Plain SVD (singular values non-negative and sorted descending by Eigen).
  Eigen::JacobiSVD<Mat3> svd(G, Eigen::ComputeFullU | Eigen::ComputeFullV);
  SignedSvd out{svd.matrixU(), svd.singularValues(), svd.matrixV()};
  // Irving's sign fix: make U and V rotations; the sign moves onto the smallest value s_3.
  if (out.U.determinant() < 0.0) {
    out.U.col(2) *= -1.0;
    out.s[2] *= -1.0;
  }
  if (out.V.determinant() < 0.0) {
    out.V.col(2) *= -1.0;
    out.s[2] *= -1.0;
  }
  return out;
}

Mat3 CalcPolarRotation(const Mat3& G) {
  const SignedSvd svd = CalcSignedSvd(G);
  return svd.U * svd.V.transpose();
}

}  // namespace taut
