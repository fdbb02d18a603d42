// Which one-sided faces of a quad hydrodynamics model (quad_hydrodynamics.h)
// the water meets at a state: where it does not, the face feels no force, and
// the force jumps where a face starts or stops meeting the water. And the
// faces' relative velocities.
#pragma once

#include <vector>

#include "diffpd/quad_hydrodynamics.h"
#include "diffpd/types.h"

namespace diffpd {

// Per face of water.quads (in order): 1 where the relative velocity u = flow
// - the face's mean corner velocity is not negligible and points against the
// face's outward normal at positions x and velocities v (3n each, m and m/s),
// 0 otherwise. Does not validate its arguments (the scene checks the model).
std::vector<char> WettedQuads(const QuadHydrodynamics& water, const VectorXd& x, const VectorXd& v);

// Per face of water.quads (column f, m/s): its relative velocity u = flow -
// the mean of its corners' velocities in v (3n). Where u passes through
// zero the force is continuous but not smooth (|u| u and the angle's jump),
// held or not. Does not validate its arguments.
Eigen::Matrix3Xd QuadRelativeVelocities(const QuadHydrodynamics& water, const VectorXd& v);

}  // namespace diffpd
