#include "solver/explicit_stability.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <Eigen/Eigenvalues>

namespace diffpd::internal {

double ExplicitStableTimeStep(SimulatorImpl& sim, const VectorXd& x) {
  constexpr int kMaxIterations = 500;
  constexpr double kRelResidual = 1e-6;
  const Eigen::Index n = x.size();
  // Mass-scaled coordinates y = M^1/2 z: the operator S = M^-1/2 K M^-1/2 is
  // symmetric with the eigenvalues of M^-1 K. Fixed DoFs are zero throughout.
  VectorXd inv_sqrt_mass = sim.Mass().cwiseSqrt().cwiseInverse();
  sim.ZeroFixed(&inv_sqrt_mass);
  StepLinearization k(sim, x, /*static_problem=*/true);
  const auto apply = [&](const VectorXd& y) -> VectorXd {
    return inv_sqrt_mass.cwiseProduct(k.Apply(inv_sqrt_mass.cwiseProduct(y)));
  };

  std::mt19937_64 rng(20211);
  std::normal_distribution<double> normal(0.0, 1.0);
  VectorXd q(n);
  for (Eigen::Index i = 0; i < n; ++i) q(i) = inv_sqrt_mass(i) == 0 ? 0.0 : normal(rng);
  if (q.norm() == 0) return std::numeric_limits<double>::infinity();
  q /= q.norm();
  VectorXd q_previous = VectorXd::Zero(n);
  std::vector<double> alpha, beta;  // T's diagonal and subdiagonal
  double largest = 0;
  double scale = 0;  // the largest |entry| of T so far
  for (int j = 0; j < kMaxIterations; ++j) {
    VectorXd w = apply(q);
    alpha.push_back(q.dot(w));
    w -= alpha.back() * q + (beta.empty() ? 0.0 : beta.back()) * q_previous;
    const double b = w.norm();
    scale = std::max({scale, std::abs(alpha.back()), b});
    const bool invariant = !(b > 1e-14 * scale);  // the Krylov space is closed: T's values are exact
    const int m = static_cast<int>(alpha.size());
    if (invariant || m % 5 == 0 || j + 1 == kMaxIterations) {
      // T's largest eigenvalue (a Ritz value) and its residual |b s_m|, s
      // its unit eigenvector.
      Eigen::SelfAdjointEigenSolver<MatrixXd> ritz;
      ritz.computeFromTridiagonal(Eigen::Map<const VectorXd>(alpha.data(), m),
                                  Eigen::Map<const VectorXd>(beta.data(), m - 1), Eigen::ComputeEigenvectors);
      largest = ritz.eigenvalues()(m - 1);
      if (invariant || std::abs(b * ritz.eigenvectors()(m - 1, m - 1)) <= kRelResidual * std::abs(largest)) break;
    }
    beta.push_back(b);
    q_previous = q;
    q = w / b;
  }
  if (!(largest > 0)) return std::numeric_limits<double>::infinity();
  return 2 / std::sqrt(largest);
}

}  // namespace diffpd::internal
