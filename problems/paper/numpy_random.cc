#include "paper/numpy_random.h"

#include <cmath>

namespace diffpd::problems {

double NumpyRandom::Uniform() {
  const std::uint32_t a = engine_() >> 5, b = engine_() >> 6;
  return (a * 67108864.0 + b) / 9007199254740992.0;
}

double NumpyRandom::Uniform(double low, double high) { return low + (high - low) * Uniform(); }

VectorXd NumpyRandom::Uniform(const VectorXd& low, const VectorXd& high) {
  VectorXd out(low.size());
  for (Eigen::Index i = 0; i < low.size(); ++i) out(i) = Uniform(low(i), high(i));
  return out;
}

double NumpyRandom::Normal(double sigma) {
  if (has_cached_normal_) {
    has_cached_normal_ = false;
    return sigma * cached_normal_;
  }
  double x1, x2, r2;
  do {
    x1 = 2.0 * Uniform() - 1.0;
    x2 = 2.0 * Uniform() - 1.0;
    r2 = x1 * x1 + x2 * x2;
  } while (r2 >= 1.0 || r2 == 0.0);
  const double f = std::sqrt(-2.0 * std::log(r2) / r2);
  cached_normal_ = f * x1;
  has_cached_normal_ = true;
  return sigma * (f * x2);
}

VectorXd NumpyRandom::Normal(int count, double sigma) {
  VectorXd out(count);
  for (int i = 0; i < count; ++i) out(i) = Normal(sigma);
  return out;
}

}  // namespace diffpd::problems
