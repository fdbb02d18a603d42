// Several starting points of the starfish fit and the choice among the fits
// from them. The fitted values that the recordings do not pin down (E, nu,
// the tendon length, the water's coefficients: starfish_fit.h) end wherever
// their start leads; fits from starts spread over the fit's intervals are
// compared by their own final cost (the calibration window's, never a
// prediction's).
#pragma once

#include <vector>

#include "calibration/starfish_actuation.h"
#include "calibration/starfish_fit.h"
#include "diffpd/material.h"

namespace diffpd::problems {

// A starting point of the fit: material (E, nu, density), actuation (slack,
// lag, length, release_lag) and water, in physical units.
struct StarfishStart {
  MaterialParameters material;
  StarfishActuation actuation;
  StarfishWater water;
};

// The most starts StarfishStarts gives.
inline constexpr int kMaxStarfishStarts = 4;

// The first `count` starting points: start 0 is `first` (the fit's default
// start), the others fixed points in other parts of the fit's intervals
// (starfish_fit.h), each with `first`'s density and, when `first` has a
// release lag, a release lag of their own:
//   1: E 1e5 Pa, nu 0.3,  slack 1 mm, lag 30 ms, length 50 mm, release 100 ms, water 0.5 / 5 / 0.5
//   2: E 2e6 Pa, nu 0.44, slack 6 mm, lag 80 ms, length 90 mm, release 30 ms,  water 0.01 / 1 / 1
//   3: E 5e4 Pa, nu 0.25, slack 8 mm, lag 20 ms, length 45 mm, release 200 ms, water 1 / 10 / 0.02
// (water: drag_tangential / drag_normal / thrust). Throws InvalidInputError
// for a count outside [1, kMaxStarfishStarts]:
//   "starfish starts: count = 5 is invalid: must be in [1, 4]".
std::vector<StarfishStart> StarfishStarts(int count, const StarfishStart& first);

// The index of the usable fit (StarfishFit::usable) with the lowest finite
// final cost; the first of equal ones; -1 when none is usable.
int BestStarfishFit(const std::vector<StarfishFit>& fits);

}  // namespace diffpd::problems
