// numpy's legacy random stream (numpy.random.seed / RandomState, MT19937),
// reproduced so that the paper's random initial guesses, normalisation draws
// and random losses are the same numbers here.
//
//   NumpyRandom rng(42);
//   rng.Uniform();        // 0.3745401188473625, then 0.9507143064099162, ...
//   rng.Normal();         // standard normal, Marsaglia's polar method
//
// Seeding uses the standard init_genrand recurrence (std::mt19937's own
// seeding). A uniform double is u = ((a >> 5) 2^26 + (b >> 6)) / 2^53 from two
// 32-bit outputs a, b. Normal() draws pairs (x1, x2) uniform in the unit disc
// (x = 2u - 1, rejecting r2 = x1^2 + x2^2 >= 1 or 0), returns x2 f with
// f = sqrt(-2 ln r2 / r2) and keeps x1 f for the next call, as numpy does.
#pragma once

#include <cstdint>
#include <random>

#include "diffpd/types.h"

namespace diffpd::problems {

class NumpyRandom {
 public:
  explicit NumpyRandom(std::uint32_t seed) : engine_(seed) {}
  // u in [0, 1) (numpy.random.random_sample).
  double Uniform();
  // low + (high - low) u (numpy.random.uniform).
  double Uniform(double low, double high);
  // One draw per entry, entry i in [low_i, high_i) (numpy.random.uniform with
  // array bounds); low and high of equal size.
  VectorXd Uniform(const VectorXd& low, const VectorXd& high);
  // sigma times a standard normal (numpy.random.normal(0, sigma)).
  double Normal(double sigma = 1.0);
  // `count` normals in order.
  VectorXd Normal(int count, double sigma = 1.0);

 private:
  std::mt19937 engine_;
  bool has_cached_normal_ = false;
  double cached_normal_ = 0;
};

}  // namespace diffpd::problems
