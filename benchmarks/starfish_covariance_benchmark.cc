// Benchmark (not a test): the Monte Carlo check of the starfish fit's
// reported standard deviations (problems/calibration/starfish_covariance_check.h)
// on the real starfish model. Synthetic recordings are simulated from the
// given parameters on a window of data_horizontal_cyclic1.csv (its tendon
// signal and marker layout), with Gaussian noise on every weighted marker
// coordinate, and refitted by the calibration's Levenberg-Marquardt fit (E,
// nu, tendon slack, lag, length, and the water's drag and thrust unless
// --no-water); the table compares the refitted values' spread with the
// median standard deviation the refits report.
//
// Usage: starfish_covariance_benchmark [--refits 20] [--noise-mm 0.5]
//   [--start 1.15] [--seconds 0.5] [--substeps 1] [--seed 1] [--no-water]
//   [--json]
// --noise-mm: the noise of each captured coordinate of the weight-1 markers
// M2, M3 (mm; M1 and M4, weighted 10, get 1/sqrt(10) of it), as the fit's
// weights assume.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include <nlohmann/json.hpp>

#include "calibration/calibrate_starfish.h"
#include "calibration/starfish_covariance_check.h"
#include "diffpd/simulator.h"
#include "shared_data.h"

using namespace diffpd;
using namespace diffpd::problems;

int main(int argc, char** argv) {
  StarfishCovarianceCheckOptions check;
  check.refits = 20;
  double noise_mm = 0.5, start = 1.15, seconds = 0.5;
  int substeps = 1;
  bool water = true, json = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> const char* {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--refits")
      check.refits = std::atoi(next());
    else if (a == "--noise-mm")
      noise_mm = std::atof(next());
    else if (a == "--start")
      start = std::atof(next());
    else if (a == "--seconds")
      seconds = std::atof(next());
    else if (a == "--substeps")
      substeps = std::atoi(next());
    else if (a == "--seed")
      check.seed = std::strtoull(next(), nullptr, 10);
    else if (a == "--no-water")
      water = false;
    else if (a == "--json")
      json = true;
    else {
      std::fprintf(stderr, "unknown option %s\n", a.c_str());
      return 2;
    }
  }
  try {
    StarfishCalibration starfish;
    starfish.set_substeps(substeps);
    starfish.set_fit_water(water);
    const StarfishRecording rec = ReadStarfishRecording(SharedDataPath("starfish/data_horizontal_cyclic1.csv"));
    const StarfishWindow window = MakeStarfishWindow(rec, start, seconds);
    const SolverOptions options = starfish.Options(Method::kPdLbfgs, 1);
    // The truth: values near the real fit's (2026-11-26 measurements).
    StarfishTruth truth{MaterialParameters{3e5, 0.38, 400}, StarfishActuation{0.002, 0.035, 0.055}, std::nullopt};
    if (water) truth.water = StarfishWater{0.3, 1.0, 0.2};
    // Weighted residuals are (2 mm)^-1 sqrt(w_m / (sum w frames)) times the
    // error: noise_mm on a weight-1 coordinate is this residual noise.
    const double frames = window.num_frames() - 1;
    check.noise = noise_mm / 2.0 * std::sqrt(1.0 / (22.0 * frames));
    const StarfishWater water_values = truth.water ? *truth.water : StarfishWater();
    Scene scene = starfish.MakeScene();
    CapturedMotion layout;
    {
      SolverOptions o = options;
      o.time_step = StarfishTimeStep(rec, window, substeps);
      Simulator sim(scene, o);
      layout = starfish.WindowMotion(scene.mesh, starfish.WindowInitialState(sim, rec, window, truth.actuation), rec,
                                     window);
    }
    const StarfishModelFactory make = [&](const CapturedMotion& motion) {
      return starfish.MakeModel(rec, window, options, truth.material, truth.actuation, water_values, &motion);
    };
    const StarfishCovarianceCheck c = CheckStarfishCovariance(make, layout, truth, check);
    if (json) {
      nlohmann::json rows = nlohmann::json::array();
      for (size_t i = 0; i < c.names.size(); ++i)
        rows.push_back({{"parameter", c.names[i]},
                        {"truth", c.truth[i]},
                        {"mean", c.mean[i]},
                        {"empirical_sd", c.empirical_sd[i]},
                        {"reported_sd", c.reported_sd[i]},
                        {"ratio", c.empirical_sd[i] / c.reported_sd[i]}});
      const nlohmann::json out = {{"refits", c.refits},   {"usable", c.usable},  {"noise_mm", noise_mm},
                                  {"start_s", start},     {"seconds", seconds},  {"substeps", substeps},
                                  {"frames", frames + 1}, {"wall_s", c.seconds}, {"parameters", rows}};
      std::printf("%s\n", out.dump(2).c_str());
      return 0;
    }
    std::printf(
        "# starfish covariance check: %d refits (%d usable), %g s of cyclic1 from %g s, %d steps per frame, "
        "noise %g mm (weight-1 markers), %.1f s\n",
        c.refits, c.usable, seconds, start, substeps, noise_mm, c.seconds);
    std::printf("%-20s %12s %12s %14s %14s %8s\n", "parameter", "truth", "mean", "refit_spread", "reported_sd",
                "ratio");
    for (size_t i = 0; i < c.names.size(); ++i)
      std::printf("%-20s %12.5g %12.5g %14.4g %14.4g %8.3f\n", c.names[i].c_str(), c.truth[i], c.mean[i],
                  c.empirical_sd[i], c.reported_sd[i], c.empirical_sd[i] / c.reported_sd[i]);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "starfish_covariance_benchmark: %s\n", e.what());
    return 1;
  }
  return 0;
}
