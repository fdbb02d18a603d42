// Penalty contact energies of candidate nodes against half-spaces (internal);
// see diffpd/contact.h. Per candidate node with gap d = n . x - offset:
//   E = (w/2) min(0, d)^2,  dE/dx = w min(0, d) n,  d2E/dx2 = w n n^T (d < 0).
// A PD vertex energy: A_s gets w on the node's diagonal.
#pragma once

#include <vector>

#include "diffpd/contact.h"
#include "diffpd/types.h"
#include "fem/fem_model.h"

namespace diffpd::internal {

class PenaltyContactEnergy {
 public:
  // Does not take ownership of fem; `contacts` must be valid (Scene::Validate).
  PenaltyContactEnergy(const FemModel& fem, const std::vector<PenaltyContact>& contacts);

  bool empty() const { return nodes_.empty(); }
  // Returns the energy (J); if grad != nullptr adds dE/dx to *grad (3n).
  double AddEnergyAndGradient(const VectorXd& x, VectorXd* grad) const;
  // Adds w n n^T of every penetrating node to the diagonal block of one
  // element incident to it (blocks as ElasticForces::ElementHessians).
  void AddElementHessians(const VectorXd& x, std::vector<double>* blocks) const;
  // *out += (d2E/dx2) z.
  void AddHessianProduct(const VectorXd& x, const VectorXd& z, VectorXd* out) const;
  // Adds w to diag(A_s) (n entries) for every candidate.
  void AddPdDiagonal(VectorXd* diagonal) const;

 private:
  struct Node {
    int node;
    Vec3 normal;  // unit
    double offset;
    double stiffness;
    int incidence;  // e * K + a of one element incident to the node
  };
  const FemModel& fem_;
  std::vector<Node> nodes_;
};

}  // namespace diffpd::internal
