// Deformation gradients in derivative tests: flattening and the input scale
// of the central-difference step rule (central_difference.h).
#pragma once

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

#include "diffpd/types.h"

namespace diffpd::testing {

// vec(F), column-major as types.h flattens (Mat9 derivatives), and back.
inline Vec9 Flatten(const Mat3& F) { return Eigen::Map<const Vec9>(F.data()); }
inline Mat3 Unflatten(const VectorXd& f) { return Eigen::Map<const Mat3>(f.data()); }

// The scale over which functions of F built on its signed SVD (energies,
// stresses, projections) change: the distance of the spectrum to where they
// are not smooth, min(|sigma_2|, sigma_1 + sigma_2) for signed singular
// values sigma_0 >= sigma_1 >= |sigma_2| (sigma_2 < 0 when det F < 0), i.e.
// to rank deficiency and to the rotation's jump at sigma_1 = -sigma_2, and
// at most 1, the scale of the rest state F = I that strains are measured
// from. The input_scale of a difference check in F.
inline double DeformationScale(const Mat3& F) {
  const Vec3 s = Eigen::JacobiSVD<Mat3>(F).singularValues();  // s0 >= s1 >= s2 >= 0
  return std::min(1.0, F.determinant() < 0 ? std::min(s(2), s(1) - s(2)) : s(2));
}

}  // namespace diffpd::testing
