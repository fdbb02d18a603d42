#include "calibration/starfish_fit_starts.h"

#include <cmath>
#include <string>

#include "diffpd/error.h"

namespace diffpd::problems {

std::vector<StarfishStart> StarfishStarts(int count, const StarfishStart& first) {
  if (count < 1 || count > kMaxStarfishStarts)
    throw InvalidInputError("starfish starts: count = " + std::to_string(count) + " is invalid: must be in [1, " +
                            std::to_string(kMaxStarfishStarts) + "]");
  struct Point {
    double youngs_modulus, poissons_ratio, slack, lag, length, release_lag;
    StarfishWater water;
  };
  // The file comment's starts 1..3 (SI units).
  static constexpr Point kOthers[kMaxStarfishStarts - 1] = {
      {1e5, 0.3, 0.001, 0.03, 0.05, 0.1, {0.5, 5, 0.5}},
      {2e6, 0.44, 0.006, 0.08, 0.09, 0.03, {0.01, 1, 1}},
      {5e4, 0.25, 0.008, 0.02, 0.045, 0.2, {1, 10, 0.02}},
  };
  std::vector<StarfishStart> starts = {first};
  for (int k = 1; k < count; ++k) {
    const Point& p = kOthers[k - 1];
    StarfishStart s;
    s.material = MaterialParameters{p.youngs_modulus, p.poissons_ratio, first.material.density};
    s.actuation = StarfishActuation{p.slack, p.lag, p.length};
    if (first.actuation.release_lag) s.actuation.release_lag = p.release_lag;
    s.water = p.water;
    starts.push_back(s);
  }
  return starts;
}

int BestStarfishFit(const std::vector<StarfishFit>& fits) {
  int best = -1;
  for (int k = 0; k < static_cast<int>(fits.size()); ++k) {
    const StarfishFit& f = fits[k];
    if (!f.usable || !std::isfinite(f.final_cost)) continue;
    if (best < 0 || f.final_cost < fits[best].final_cost) best = k;
  }
  return best;
}

}  // namespace diffpd::problems
