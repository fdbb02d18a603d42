#include "calibration/starfish_covariance_check.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <sstream>
#include <stdexcept>

#include "diffpd/error.h"

namespace diffpd::problems {

StarfishCovarianceCheck CheckStarfishCovariance(const StarfishModelFactory& make_model, const CapturedMotion& layout,
                                                const StarfishTruth& truth,
                                                const StarfishCovarianceCheckOptions& options) {
  if (options.refits < 2)
    throw InvalidInputError("refits = " + std::to_string(options.refits) + " is invalid: must be >= 2");
  if (!(std::isfinite(options.noise) && options.noise > 0)) {
    std::ostringstream msg;
    msg << "noise = " << options.noise << " is invalid: must be finite and > 0";
    throw InvalidInputError(msg.str());
  }
  const auto begin = std::chrono::steady_clock::now();
  StarfishCovarianceCheck check;
  StarfishFit truth_fit;
  truth_fit.material = truth.material;
  truth_fit.actuation = truth.actuation;
  truth_fit.water_fitted = truth.water.has_value();
  if (truth.water) truth_fit.water = *truth.water;
  check.names = StarfishFitNames(truth.actuation.release_lag.has_value(), truth_fit.water_fitted);
  check.truth = StarfishFitValues(truth_fit);
  const int n = static_cast<int>(check.truth.size());

  // The simulated positions at the truth: layout + residual / weight.
  std::unique_ptr<solvers::RolloutFunction> model = make_model(layout);
  VectorXd r;
  const Eigen::Map<const VectorXd> p_truth(check.truth.data(), n);
  if (!model->Evaluate(p_truth, model->RowsOf(0), &r, nullptr))
    throw std::runtime_error("the model fails at the truth: " + model->statistics().last_error);
  DIFFPD_CHECK(r.size() == 3 * static_cast<Eigen::Index>(layout.samples.size()),
               "functional 0 has one row per sample and axis");
  CapturedMotion clean = layout;
  for (size_t s = 0; s < clean.samples.size(); ++s)
    for (int d = 0; d < 3; ++d) {
      const double w = clean.samples[s].weight(d);
      if (w > 0) clean.samples[s].position(d) += r(3 * static_cast<Eigen::Index>(s) + d) / w;
    }

  std::mt19937_64 random(options.seed);
  std::normal_distribution<double> normal(0.0, options.noise);
  std::vector<std::vector<double>> values(n), reported(n);
  const StarfishWater* water = truth.water ? &*truth.water : nullptr;
  for (int k = 0; k < options.refits; ++k) {
    CapturedMotion noisy = clean;
    for (MarkerSample& s : noisy.samples)
      for (int d = 0; d < 3; ++d)
        if (s.weight(d) > 0) s.position(d) += normal(random) / s.weight(d);
    std::unique_ptr<solvers::RolloutFunction> refit_model = make_model(noisy);
    const StarfishFit fit = FitStarfishLeastSquares(refit_model.get(), 0, truth.material, truth.actuation, water,
                                                    options.max_iterations, nullptr);
    ++check.refits;
    if (!fit.usable || static_cast<int>(fit.standard_deviation.size()) != n) continue;
    ++check.usable;
    const std::vector<double> x = StarfishFitValues(fit);
    for (int i = 0; i < n; ++i) {
      values[i].push_back(x[i]);
      reported[i].push_back(fit.standard_deviation[i]);
    }
  }
  if (check.usable < 2)
    throw std::runtime_error("only " + std::to_string(check.usable) + " of " + std::to_string(check.refits) +
                             " refits are usable");
  for (int i = 0; i < n; ++i) {
    double mean = 0;
    for (double v : values[i]) mean += v / check.usable;
    double var = 0;
    for (double v : values[i]) var += (v - mean) * (v - mean) / (check.usable - 1);
    std::vector<double> sd = reported[i];
    std::nth_element(sd.begin(), sd.begin() + sd.size() / 2, sd.end());
    check.mean.push_back(mean);
    check.empirical_sd.push_back(std::sqrt(var));
    check.reported_sd.push_back(sd[sd.size() / 2]);
  }
  check.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  return check;
}

}  // namespace diffpd::problems
