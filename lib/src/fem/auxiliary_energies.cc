#include "fem/auxiliary_energies.h"

namespace diffpd::internal {

AuxiliaryEnergies::AuxiliaryEnergies(const FemModel& fem, const Scene& scene)
    : fem_(fem), muscles_(fem, scene.muscles), penalty_(fem, scene.penalty_contacts) {}

double AuxiliaryEnergies::AddEnergyAndGradient(const VectorXd& x, const VectorXd& activation, VectorXd* grad) const {
  if (empty()) return 0.0;
  return muscles_.AddEnergyAndGradient(x, activation, grad) + penalty_.AddEnergyAndGradient(x, grad);
}

void AuxiliaryEnergies::AddElementHessians(const VectorXd& x, const VectorXd& activation, bool project_spd,
                                           std::vector<double>* blocks) const {
  if (empty()) return;
  muscles_.AddElementHessians(x, activation, project_spd, blocks);
  penalty_.AddElementHessians(x, blocks);
}

void AuxiliaryEnergies::AddHessianProduct(const VectorXd& x, const VectorXd& activation, const VectorXd& z,
                                          VectorXd* out) const {
  if (empty()) return;
  muscles_.AddHessianProduct(x, activation, z, out);
  penalty_.AddHessianProduct(x, z, out);
}

SparseMatrix AuxiliaryEnergies::PdMatrix() const {
  if (empty()) return SparseMatrix();
  const int n = fem_.num_nodes();
  std::vector<Eigen::Triplet<double>> triplets;
  muscles_.AddPdTriplets(&triplets);
  VectorXd diagonal = VectorXd::Zero(n);
  penalty_.AddPdDiagonal(&diagonal);
  for (int i = 0; i < n; ++i)
    if (diagonal(i) != 0) triplets.emplace_back(i, i, diagonal(i));
  SparseMatrix m(n, n);
  m.setFromTriplets(triplets.begin(), triplets.end());
  m.makeCompressed();
  return m;
}

}  // namespace diffpd::internal
