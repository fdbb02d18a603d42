#include "solver/rigid_mode_correction.h"

#include <algorithm>

#include <Eigen/Eigenvalues>

#include "diffpd/error.h"
#include "solver/simulator_impl.h"

namespace diffpd::internal {
namespace {

// Eigenvalues of E below this fraction of its largest are dropped (rounding
// of modes the fixed DoFs nearly removed).
constexpr double kRelativeEigenvalueFloor = 1e-12;

}  // namespace

RigidModeCorrection::RigidModeCorrection(const VectorXd& x, const std::vector<char>& fixed) {
  const Eigen::Index dofs = x.size();
  DIFFPD_CHECK(dofs % 3 == 0 && static_cast<Eigen::Index>(fixed.size()) == dofs,
               "RigidModeCorrection: " << dofs << " positions, " << fixed.size() << " flags");
  const Eigen::Index n = dofs / 3;
  Vec3 centre = Vec3::Zero();
  for (Eigen::Index i = 0; i < n; ++i) centre += x.segment<3>(3 * i);
  if (n > 0) centre /= static_cast<double>(n);
  uncut_ = MatrixXd::Zero(dofs, kModes);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Vec3 p = x.segment<3>(3 * i) - centre;
    for (int a = 0; a < 3; ++a) {
      uncut_(3 * i + a, a) = 1;                                   // translation along a
      uncut_.block<3, 1>(3 * i, 3 + a) = Vec3::Unit(a).cross(p);  // rotation about a
    }
  }
  modes_ = uncut_;
  for (Eigen::Index d = 0; d < dofs; ++d)
    if (fixed[d]) modes_.row(d).setZero();
  for (int k = 0; k < kModes; ++k) {
    const double norm = modes_.col(k).norm();
    scale_(k) = norm > 0 ? 1 / norm : 0.0;
    modes_.col(k) *= scale_(k);
  }
}

void RigidModeCorrection::SetHessianProducts(const MatrixXd& hz) {
  DIFFPD_CHECK(hz.rows() == modes_.rows() && hz.cols() == kModes,
               "RigidModeCorrection: H Z is " << hz.rows() << " x " << hz.cols());
  // Coefficient-wise products: Eigen's blocked GEMM would open an OpenMP
  // team for these thin ones (6 columns).
  Eigen::Matrix<double, kModes, kModes> e = modes_.transpose().lazyProduct(hz);
  e = (0.5 * (e + e.transpose())).eval();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, kModes, kModes>> eig(e);
  const auto& values = eig.eigenvalues();
  const double floor = kRelativeEigenvalueFloor * values.cwiseAbs().maxCoeff();
  Eigen::Matrix<double, kModes, 1> inverse = Eigen::Matrix<double, kModes, 1>::Zero();
  for (int k = 0; k < kModes; ++k)
    if (values(k) > floor) inverse(k) = 1 / values(k);
  pseudo_inverse_ = eig.eigenvectors() * inverse.asDiagonal() * eig.eigenvectors().transpose();
}

void RigidModeCorrection::Add(const MatrixXd& r, MatrixXd* out) const {
  const MatrixXd coarse = pseudo_inverse_ * modes_.transpose().lazyProduct(r);
  *out += modes_.lazyProduct(coarse);
}

void RigidModeCorrection::Add(const VectorXd& r, VectorXd* out) const {
  *out += modes_ * (pseudo_inverse_ * (modes_.transpose() * r));
}

MatrixXd RigidModeHessianProducts(SimulatorImpl& sim, const RigidModeCorrection& rigid, const VectorXd& x,
                                  const VectorXd& elastic_gradient, const VectorXd& inertia) {
  const Eigen::Index dofs = x.size();
  const int k = RigidModeCorrection::kModes;
  const MatrixXd& uncut = rigid.uncut_modes();
  DIFFPD_CHECK(elastic_gradient.size() == dofs,
               "RigidModeHessianProducts: gradient of size " << elastic_gradient.size());
  // Elastic part on the uncut modes, from the frame indifference of E (rows
  // of fixed DoFs are zeroed at the end).
  MatrixXd h = MatrixXd::Zero(dofs, k);
  for (Eigen::Index i = 0; i < dofs / 3; ++i)
    for (int a = 0; a < 3; ++a)
      h.block<3, 1>(3 * i, 3 + a) = Vec3::Unit(a).cross(Vec3(elastic_gradient.segment<3>(3 * i)));
  // Minus its product with the cut part (uncut - Z's support), which lives
  // on the fixed DoFs: only elements with a fixed DoF contribute.
  MatrixXd cut = MatrixXd::Zero(dofs, k);
  bool any_fixed = false;
  for (Eigen::Index d = 0; d < dofs; ++d)
    if (sim.fixed[d]) {
      cut.row(d) = uncut.row(d);
      any_fixed = true;
    }
  if (any_fixed) {
    // The elements around the fixed nodes, ascending, from the node ->
    // element adjacency (incidence e K + a).
    const int per_element = sim.fem.nodes_per_element();
    const std::vector<int>& offsets = sim.fem.node_offsets();
    const std::vector<int>& incidences = sim.fem.node_incidences();
    std::vector<int> elements;
    for (int node = 0; node < sim.fem.num_nodes(); ++node) {
      if (!(sim.fixed[3 * node] || sim.fixed[3 * node + 1] || sim.fixed[3 * node + 2])) continue;
      for (int j = offsets[node]; j < offsets[node + 1]; ++j) elements.push_back(incidences[j] / per_element);
    }
    std::sort(elements.begin(), elements.end());
    elements.erase(std::unique(elements.begin(), elements.end()), elements.end());
    MatrixXd h_cut = MatrixXd::Zero(dofs, k);
    sim.elastic.AddElementHessianProducts(x, sim.lame(), elements, cut, &h_cut);
    h -= h_cut;
  }
  h *= rigid.scale().asDiagonal();
  // Inertia and the auxiliary energies (penalty contact is not frame
  // indifferent) on Z itself.
  const MatrixXd& z = rigid.modes();
  for (int c = 0; c < k; ++c) {
    VectorXd hz = VectorXd::Zero(dofs);
    sim.aux.AddHessianProduct(x, sim.activation, z.col(c), &hz);
    h.col(c) += hz + inertia.cwiseProduct(z.col(c));
  }
  for (Eigen::Index d = 0; d < dofs; ++d)
    if (sim.fixed[d]) h.row(d).setZero();
  return h;
}

}  // namespace diffpd::internal
