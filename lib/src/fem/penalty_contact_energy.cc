#include "fem/penalty_contact_energy.h"

namespace diffpd::internal {

PenaltyContactEnergy::PenaltyContactEnergy(const FemModel& fem, const std::vector<PenaltyContact>& contacts)
    : fem_(fem) {
  for (const PenaltyContact& c : contacts) {
    const Vec3 n = c.normal.normalized();
    for (const int i : c.nodes)
      nodes_.push_back(Node{i, n, c.offset, c.stiffness, fem.node_incidences()[fem.node_offsets()[i]]});
  }
}

double PenaltyContactEnergy::AddEnergyAndGradient(const VectorXd& x, VectorXd* grad) const {
  double energy = 0;
  for (const Node& nd : nodes_) {
    const double gap = nd.normal.dot(x.segment<3>(3 * nd.node)) - nd.offset;
    if (gap >= 0) continue;
    energy += 0.5 * nd.stiffness * gap * gap;
    if (grad) grad->segment<3>(3 * nd.node) += nd.stiffness * gap * nd.normal;
  }
  return energy;
}

void PenaltyContactEnergy::AddElementHessians(const VectorXd& x, std::vector<double>* blocks) const {
  const int k = fem_.nodes_per_element();
  const int nb = 3 * k;
  for (const Node& nd : nodes_) {
    if (nd.normal.dot(x.segment<3>(3 * nd.node)) - nd.offset >= 0) continue;
    const int e = nd.incidence / k, a = nd.incidence % k;
    double* ke = blocks->data() + static_cast<size_t>(e) * nb * nb;
    const Mat3 h = nd.stiffness * nd.normal * nd.normal.transpose();
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) ke[(3 * a + j) * nb + 3 * a + i] += h(i, j);
  }
}

void PenaltyContactEnergy::AddHessianProduct(const VectorXd& x, const VectorXd& z, VectorXd* out) const {
  for (const Node& nd : nodes_) {
    if (nd.normal.dot(x.segment<3>(3 * nd.node)) - nd.offset >= 0) continue;
    out->segment<3>(3 * nd.node) += nd.stiffness * nd.normal.dot(z.segment<3>(3 * nd.node)) * nd.normal;
  }
}

void PenaltyContactEnergy::AddPdDiagonal(VectorXd* diagonal) const {
  for (const Node& nd : nodes_) (*diagonal)(nd.node) += nd.stiffness;
}

}  // namespace diffpd::internal
