// The settings every material fit of the calibration problems shares:
// Young's modulus and density step in log space, Poisson's ratio linearly
// within [0.01, 0.49]; Levenberg-Marquardt with dense QR, stopping
// tolerances above the forward solves' noise, and the parameter block
// updated at every iteration (for the iteration table).
#pragma once

#include <vector>

#include <ceres/problem.h>
#include <ceres/solver.h>

#include "diffpd/solvers/core/material_block.h"

namespace diffpd::problems {

// Sets the manifold and bounds of `block` (fields.size() values, in
// `fields` order; the problem takes ownership of the manifold).
void SetMaterialCoordinates(ceres::Problem* problem, double* block, const std::vector<solvers::MaterialField>& fields);

ceres::Solver::Options MaterialFitOptions(int max_iterations);

}  // namespace diffpd::problems
