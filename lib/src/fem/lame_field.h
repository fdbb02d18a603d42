// Lame parameters over the elements of a mesh (internal): one uniform pair
// (mu, lambda), or one pair per element (material regions, directions of
// per-region parameters). A view: it does not own the per-element arrays,
// which must outlive it.
#pragma once

namespace diffpd::internal {

struct LameField {
  double mu = 0;                           // Pa, used when element_mu is nullptr
  double lambda = 0;                       // Pa, used when element_lambda is nullptr
  const double* element_mu = nullptr;      // num_elements values (Pa), or nullptr
  const double* element_lambda = nullptr;  // num_elements values (Pa), or nullptr

  static LameField Uniform(double mu, double lambda) { return LameField{mu, lambda, nullptr, nullptr}; }
  // Per-element arrays (both non-null).
  static LameField PerElement(const double* mu, const double* lambda) { return LameField{0, 0, mu, lambda}; }

  double mu_of(int e) const { return element_mu ? element_mu[e] : mu; }
  double lambda_of(int e) const { return element_lambda ? element_lambda[e] : lambda; }
};

}  // namespace diffpd::internal
