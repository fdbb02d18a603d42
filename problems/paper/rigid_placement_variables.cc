#include "paper/rigid_placement_variables.h"

#include <cmath>
#include <sstream>

#include "diffpd/error.h"

namespace diffpd::problems {
namespace {

Mat3 RotX(double a, bool derivative) {
  const double c = std::cos(a), s = std::sin(a);
  Mat3 r;
  if (derivative)
    r << 0, 0, 0, 0, -s, -c, 0, c, -s;
  else
    r << 1, 0, 0, 0, c, -s, 0, s, c;
  return r;
}

Mat3 RotY(double a, bool derivative) {
  const double c = std::cos(a), s = std::sin(a);
  Mat3 r;
  if (derivative)
    r << -s, 0, c, 0, 0, 0, -c, 0, -s;
  else
    r << c, 0, s, 0, 1, 0, -s, 0, c;
  return r;
}

Mat3 RotZ(double a, bool derivative) {
  const double c = std::cos(a), s = std::sin(a);
  Mat3 r;
  if (derivative)
    r << -s, -c, 0, c, -s, 0, 0, 0, 0;
  else
    r << c, -s, 0, s, c, 0, 0, 0, 1;
  return r;
}

}  // namespace

Mat3 RigidPlacementVariables::Rotation(const Vec3& rpy, Mat3 derivatives[3]) {
  const Mat3 rx = RotX(rpy(0), false), ry = RotY(rpy(1), false), rz = RotZ(rpy(2), false);
  if (derivatives) {
    derivatives[0] = rz * ry * RotX(rpy(0), true);
    derivatives[1] = rz * RotY(rpy(1), true) * rx;
    derivatives[2] = RotZ(rpy(2), true) * ry * rx;
  }
  return rz * ry * rx;
}

RigidPlacementVariables::RigidPlacementVariables(const VectorXd& rest_positions) : ReverseModeBlock(9) {
  if (rest_positions.size() == 0 || rest_positions.size() % 3 != 0) {
    std::ostringstream msg;
    msg << "rigid_placement: rest_positions has " << rest_positions.size()
        << " entries (expected 3n > 0, x y z per node)";
    throw InvalidInputError(msg.str());
  }
  offsets_ = Eigen::Map<const Eigen::Matrix3Xd>(rest_positions.data(), 3, rest_positions.size() / 3);
  const Vec3 mean = offsets_.rowwise().mean();
  offsets_.colwise() -= mean;
}

void RigidPlacementVariables::CheckFits(const Scene& scene, int num_steps) const {
  if (scene.mesh.num_vertices() != offsets_.cols()) {
    std::ostringstream msg;
    msg << "rigid_placement: made for " << offsets_.cols() << " nodes, the mesh has " << scene.mesh.num_vertices();
    throw InvalidInputError(msg.str());
  }
}

void RigidPlacementVariables::Apply(const Eigen::Ref<const VectorXd>& values, solvers::RolloutSetup* setup) const {
  const Mat3 r = Rotation(values.head<3>());
  const Vec3 c = values.segment<3>(3), u = values.segment<3>(6);
  for (Eigen::Index i = 0; i < offsets_.cols(); ++i) {
    setup->initial.x.segment<3>(3 * i) = r * offsets_.col(i) + c;
    setup->initial.v.segment<3>(3 * i) += u;
  }
}

void RigidPlacementVariables::PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                                       Eigen::Ref<VectorXd> out) const {
  Mat3 dr[3];
  Rotation(values.head<3>(), dr);
  out.setZero();
  for (Eigen::Index i = 0; i < offsets_.cols(); ++i) {
    const Vec3 gx = grad.x0.segment<3>(3 * i);
    for (int a = 0; a < 3; ++a) out(a) += gx.dot(dr[a] * offsets_.col(i));
    out.segment<3>(3) += gx;
    out.segment<3>(6) += grad.v0.segment<3>(3 * i);
  }
}

}  // namespace diffpd::problems
