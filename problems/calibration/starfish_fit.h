// The starfish fit: material and tendon actuation parameters of a rollout
// function (StarfishCalibration::MakeModel) fitted to a recording with
// Ceres, bounded by the library's CoordinateManifold.
//
// The fitted values x (physical units) and their bounds, each a log-logit
// coordinate (coordinate_manifold.h) unless said otherwise:
//   x0 E      in (1e4, 5e6) Pa
//   x1 nu     in (0.2, 0.45)
//   x2 slack  in (0, 15) mm (logit)
//   x3 lag    in (1, 500) ms
//   x4 length in (30, 130) mm
//   x5 E_arms in (1e4, 5e6) Pa (StarfishRegions::kBodyArms only; the arms'
//      nu is tied to the body's)
// in the least-squares fit with an asymmetric servo (StarfishActuation::
// release_lag set) also the release lag, log-logit like the lag:
//   release_lag in (1, 500) ms
// and, in the least-squares fit when the water is fitted (StarfishWater),
// three more, log-logit (positive: each term opposes the motion):
//   drag_tangential in (0.005, 5), drag_normal in (0.2, 20), thrust in (0.001, 10)
// and when chosen (StarfishMassDamping), log-logit:
//   density        in (50, 5000) kg/m^3 (the body's mass with the water it carries)
//   linear_damping in (0.01, 100) 1/s (Scene::linear_damping)
#pragma once

#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "calibration/starfish_actuation.h"
#include "diffpd/material.h"
#include "diffpd/solvers/ceres/coordinate_manifold.h"
#include "diffpd/solvers/core/rollout_function.h"

namespace diffpd::problems {

// The water's coefficients of the starfish (Hydrodynamics, state_forces.h):
// the scene's drag and thrust (the defaults), or the fitted values.
struct StarfishWater {
  double drag_tangential = 0.05;  // Cd along the face
  double drag_normal = 2.05;      // Cd normal to the face
  double thrust = 0;              // Ct normal to the face
};
// The maps of drag_tangential, drag_normal and thrust (file comment).
std::vector<solvers::CoordinateMap> StarfishWaterCoordinates();
// Throws InvalidInputError for a value outside its interval, e.g.
//   "drag_normal = 30 is outside the fit's interval (0.2, 20)".
void CheckStarfishWaterStart(const StarfishWater& water);

// The body's density and linear damping in the least-squares fit: fitted
// when chosen (default: neither; the scene's density and no damping).
struct StarfishMassDamping {
  bool fit_density = false;                    // from the material guess's density
  std::optional<double> linear_damping_guess;  // 1/s; set: linear_damping fitted from it
};
// Throws InvalidInputError for a value outside its interval, e.g.
//   "density = 9000 is outside the fit's interval (50, 5000) kg/m^3",
//   "linear_damping = 200 is outside the fit's interval (0.01, 100) 1/s".
void CheckStarfishMassDampingStart(double density, const StarfishMassDamping& mass_damping);

// How a fit minimises the marker error.
enum class StarfishFitMethod {
  kLbfgs,               // FitStarfishLoss: L-BFGS on the scalar loss (one adjoint per gradient)
  kLevenbergMarquardt,  // FitStarfishLeastSquares: per-frame residuals, forward-mode Jacobians
};
// "lbfgs", "lm".
const char* ToString(StarfishFitMethod method);
// Throws InvalidInputError for other names:
//   "--fit = 'newton' is invalid: calibrate-starfish fits with 'lm' or 'lbfgs'".
StarfishFitMethod ParseStarfishFitMethod(const std::string& name);

// The outcome of a fit.
struct StarfishFit {
  MaterialParameters material;  // fitted (the body's with kBodyArms)
  // kBodyArms: the arms' fitted material (E fitted; nu = material's,
  // density = material's); empty otherwise.
  std::vector<MaterialParameters> region_materials;
  StarfishActuation actuation;  // fitted
  StarfishWater water;          // fitted when water_fitted, else the scene's
  bool water_fitted = false;
  bool density_fitted = false;           // material.density fitted
  std::optional<double> linear_damping;  // 1/s, fitted; unset: no damping
  double initial_cost = 0;               // the model's loss at the start
  double final_cost = 0;
  int iterations = 0;                     // Ceres iterations
  bool usable = false;                    // Ceres' solution is usable
  std::string termination;                // Ceres' message
  solvers::RolloutStatistics statistics;  // rollouts, gradients, timings
  // FitStarfishLeastSquares only (empty otherwise): per fitted value (in the
  // order of StarfishFitNames: n values) its standard deviation from ceres::Covariance (physical units;
  // the residuals scaled by their fitted noise, s^2 = |r|^2 / (rows - n)),
  // the n x n correlation matrix (row-major), and whether the value lies at
  // a bound of its interval (tangent coordinate |u| > 5: within 1% of an
  // end), where the interval is not meaningful.
  std::vector<double> standard_deviation;
  std::vector<double> correlation;
  std::vector<bool> at_bound;
  int residuals = 0;  // rows of the least-squares problem with non-zero weight
};

// The names of the least-squares fit's values in their order: youngs_modulus,
// poissons_ratio, with `density` density, then tendon_slack, tendon_lag,
// tendon_length, then with `release` tendon_release_lag, then with `water`
// drag_tangential, drag_normal, thrust, then with `damping` linear_damping.
std::vector<std::string> StarfishFitNames(bool release, bool water, bool density = false, bool damping = false);
// A fit's values in the order of StarfishFitNames(fit.actuation.release_lag,
// fit.water_fitted, fit.density_fitted, fit.linear_damping) (physical units).
std::vector<double> StarfishFitValues(const StarfishFit& fit);

// The coordinate maps of the fitted values (5, or 6 with `arms`).
std::vector<solvers::CoordinateMap> StarfishFitCoordinates(bool arms);
// The fitted values of a starting point. Throws InvalidInputError for a
// value outside its open interval, e.g.
//   "youngs_modulus = 6e+06 is outside the fit's interval (1e4, 5e6) Pa",
//   "tendon slack = 0.02 is outside the fit's interval (0, 0.015) m".
std::vector<double> StarfishFitStart(const MaterialParameters& material, const StarfishActuation& actuation, bool arms);

// Fits `model` (blocks: material {E, nu} or, with `arms`, {E, nu, E_arms,
// nu_arms}, then TendonActuationBlock; functional 0: a scalar loss) with
// Ceres' L-BFGS (GradientProblem on the manifold of StarfishFitCoordinates)
// from `guess` (both regions) and `actuation_guess`, at most
// `max_iterations` iterations; the iteration table goes to `log` (nullptr:
// silent). A failed rollout makes Ceres shorten its step (the failure is
// counted in statistics). `density` of the result is guess.density.
StarfishFit FitStarfishLoss(solvers::RolloutFunction* model, bool arms, const MaterialParameters& guess,
                            const StarfishActuation& actuation_guess, int max_iterations, FILE* log);

// Fits `model` (blocks: material {E, nu} ({E, nu, density} with
// mass_damping.fit_density), then TendonActuationBlock (with release_lag
// when actuation_guess has one: then it is fitted too), with `water_guess`
// a StateForceBlock {drag_tangential, drag_normal, thrust}, and with
// mass_damping.linear_damping_guess a StateForceBlock {linear_damping};
// functional `residual_functional`: a MarkerResiduals) by
// Levenberg-Marquardt (ceres::Problem, one residual block per capture frame,
// Jacobians by the rollout function: forward-mode tangents for 5 to 9
// parameters) on the manifolds of StarfishFitCoordinates(false) and
// StarfishWaterCoordinates() (the release lag: the lag's), from `guess`,
// `actuation_guess` and
// `water_guess` (nullptr: the water is not fitted), at most `max_iterations`
// iterations, then the parameters' covariance (see StarfishFit). The
// iteration table goes to `log` (nullptr: silent). Throws what
// StarfishFitStart, CheckStarfishWaterStart and
// CheckStarfishMassDampingStart throw.
StarfishFit FitStarfishLeastSquares(solvers::RolloutFunction* model, int residual_functional,
                                    const MaterialParameters& guess, const StarfishActuation& actuation_guess,
                                    const StarfishWater* water_guess, int max_iterations, FILE* log,
                                    const StarfishMassDamping& mass_damping = StarfishMassDamping());

}  // namespace diffpd::problems
