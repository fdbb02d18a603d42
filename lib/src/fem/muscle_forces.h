// Muscle fibre energies of a discretised body (internal); see diffpd/muscle.h.
//
// Per sample s of a muscle element e with fibre m (unit), activation a and
// weight w = k vol_s, the feature is u = F_s m = sum_a c_a x_a with the
// scalar coefficients c_a = grad_a(s) . m, and
//   E_s = (w/2)(|u| - a)^2,          dE_s/dx_a = c_a w (u - a u^),
//   d2E_s/dx_a dx_b = c_a c_b w (I - (a/|u|)(I - u^ u^^T)),
//   d(dE_s/dx_a)/da = -c_a w u^,     u^ = u / |u| (m where |u| < 1e-12).
// The PD matrix term w G^T G is scalar: A_s(a, b) += w c_a c_b (times I3).
#pragma once

#include <vector>

#include <Eigen/SparseCore>

#include "diffpd/muscle.h"
#include "diffpd/types.h"
#include "fem/fem_model.h"

namespace diffpd::internal {

class MuscleForces {
 public:
  // Does not take ownership of fem; `muscles` must be valid (Scene::Validate).
  MuscleForces(const FemModel& fem, const std::vector<Muscle>& muscles);

  int num_muscles() const { return num_muscles_; }
  bool empty() const { return samples_.empty(); }

  // Activation of muscle j: activation(j), or 1 (rest) if activation is empty.
  // Returns the muscle energy (J) and, if grad != nullptr, adds dE/dx to *grad (3n).
  double AddEnergyAndGradient(const VectorXd& x, const VectorXd& activation, VectorXd* grad) const;
  // Adds the muscle Hessian to the element blocks (3K x 3K column-major per
  // element, as ElasticForces::ElementHessians). With project_spd each
  // sample's 3x3 factor is clamped to positive semi-definite.
  void AddElementHessians(const VectorXd& x, const VectorXd& activation, bool project_spd,
                          std::vector<double>* blocks) const;
  // *out += (d2E/dx2) z.
  void AddHessianProduct(const VectorXd& x, const VectorXd& activation, const VectorXd& z, VectorXd* out) const;
  // Per muscle j: -z . d(dE/dx)/da_j (the adjoint's dL/da_j).
  VectorXd ActivationGradient(const VectorXd& x, const VectorXd& activation, const VectorXd& z) const;
  // Adds w c_a c_b for every sample to the scalar n x n PD matrix triplets.
  void AddPdTriplets(std::vector<Eigen::Triplet<double>>* triplets) const;

 private:
  struct Sample {
    int muscle;
    int element;
    double weight;  // k vol_s
    Vec3 fiber;     // unit
  };
  double Activation(const VectorXd& activation, int muscle) const;
  Vec3 Feature(const VectorXd& x, size_t s) const;
  const double* coefficients(size_t s) const { return coefficients_.data() + s * k_; }
  const int* nodes(size_t s) const { return nodes_.data() + s * k_; }
  // The loops over samples for K nodes per element (K = 4, 8: unrolled;
  // 0: any).
  template <int K>
  double EnergyAndGradientImpl(const VectorXd& x, const VectorXd& activation, VectorXd* grad) const;
  template <int K>
  void HessianProductImpl(const VectorXd& x, const VectorXd& activation, const VectorXd& z, VectorXd* out) const;
  // Hexahedra (8 nodes, 8 samples per element): a muscle element's 8
  // features at once, U = X C (X 3 x 8 node values, C 8 x 8 coefficients),
  // and the forces back as F C^T.
  double HexEnergyAndGradient(const VectorXd& x, const VectorXd& activation, VectorXd* grad) const;
  void HexHessianProduct(const VectorXd& x, const VectorXd& activation, const VectorXd& z, VectorXd* out) const;
  bool hex_groups() const { return k_ == 8 && q_ == 8; }

  const FemModel& fem_;
  int k_ = 0;
  int q_ = 0;  // samples per element; a muscle element's samples are consecutive
  int num_muscles_ = 0;
  std::vector<Sample> samples_;
  std::vector<double> coefficients_;  // K per sample: c_a
  std::vector<int> nodes_;            // K per sample: the element's nodes
};

}  // namespace diffpd::internal
