// The energies a scene declares besides elasticity (internal): muscle fibres
// and penalty contact. One object the solvers hook into; every method returns
// at once when the scene declares none of them (zero cost).
#pragma once

#include <vector>

#include <Eigen/SparseCore>

#include "diffpd/scene.h"
#include "diffpd/types.h"
#include "fem/fem_model.h"
#include "fem/muscle_forces.h"
#include "fem/penalty_contact_energy.h"

namespace diffpd::internal {

class AuxiliaryEnergies {
 public:
  // Does not take ownership of fem; the scene must be valid.
  AuxiliaryEnergies(const FemModel& fem, const Scene& scene);

  bool empty() const { return muscles_.empty() && penalty_.empty(); }
  int num_muscles() const { return muscles_.num_muscles(); }
  const MuscleForces& muscles() const { return muscles_; }

  // activation: one entry per muscle, or empty for rest (all 1).
  // Returns the energy (J); if grad != nullptr adds dE/dx to *grad (3n).
  double AddEnergyAndGradient(const VectorXd& x, const VectorXd& activation, VectorXd* grad) const;
  // Adds the Hessian to the element blocks (see ElasticForces::ElementHessians).
  void AddElementHessians(const VectorXd& x, const VectorXd& activation, bool project_spd,
                          std::vector<double>* blocks) const;
  // *out += (d2E/dx2) z.
  void AddHessianProduct(const VectorXd& x, const VectorXd& activation, const VectorXd& z, VectorXd* out) const;
  // The constant scalar n x n term these energies add to the PD matrix A_s
  // (sum w G^T G); an empty (0 x 0) matrix when there is none.
  SparseMatrix PdMatrix() const;

 private:
  const FemModel& fem_;
  MuscleForces muscles_;
  PenaltyContactEnergy penalty_;
};

}  // namespace diffpd::internal
