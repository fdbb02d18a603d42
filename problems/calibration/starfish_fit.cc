#include "calibration/starfish_fit.h"

#include <cmath>
#include <sstream>

#include <ceres/covariance.h>
#include <ceres/gradient_problem.h>
#include <ceres/gradient_problem_solver.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include "diffpd/error.h"
#include "diffpd/solvers/ceres/rollout_cost_function.h"
#include "diffpd/solvers/ceres/rollout_evaluation_callback.h"

namespace diffpd::problems {
namespace {

constexpr double kMm = 1e-3;
constexpr double kMinE = 1e4, kMaxE = 5e6, kMinNu = 0.2, kMaxNu = 0.45;
constexpr double kMaxSlack = 0.015;                     // m
constexpr double kMinLag = 1e-3, kMaxLag = 0.5;         // s
constexpr double kMinLength = 0.03, kMaxLength = 0.13;  // m
// The water's coefficients stay positive: every term opposes the motion it
// comes from (a negative thrust below -drag_normal would push a face along
// its own normal motion, feeding energy into the body).
constexpr double kMinDragTangential = 0.005, kMaxDragTangential = 5;
constexpr double kMinDragNormal = 0.2, kMaxDragNormal = 20;
constexpr double kMinThrust = 1e-3, kMaxThrust = 10;
constexpr double kMinDensity = 50, kMaxDensity = 5000;   // kg/m^3
constexpr double kMinDamping = 0.01, kMaxDamping = 100;  // 1/s

std::string Num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// The model's parameters of the fitted values x (file comment): x0, x1
// (and x5, x1 for the arms' region), then x2..x4.
VectorXd ModelParameters(const double* x, bool arms) {
  VectorXd p(arms ? 7 : 5);
  if (arms)
    p << x[0], x[1], x[5], x[1], x[2], x[3], x[4];
  else
    p << x[0], x[1], x[2], x[3], x[4];
  return p;
}

// The model's loss as a function of the fitted values (the tie of the arms'
// nu to the body's is the only change of variables; the bounds are the
// manifold's).
class StarfishLoss : public ceres::FirstOrderFunction {
 public:
  StarfishLoss(solvers::RolloutFunction* model, bool arms) : model_(model), arms_(arms) {}
  bool Evaluate(const double* x, double* cost, double* gradient) const override {
    const VectorXd p = ModelParameters(x, arms_);
    if (gradient) {
      VectorXd g;
      if (!model_->Gradient(p, VectorXd::Ones(1), &g, cost)) return false;
      const int a = arms_ ? 4 : 2;  // the actuation block's first entry
      gradient[0] = g(0);
      gradient[1] = arms_ ? g(1) + g(3) : g(1);
      for (int j = 0; j < 3; ++j) gradient[2 + j] = g(a + j);
      if (arms_) gradient[5] = g(2);
    } else {
      VectorXd value;
      if (!model_->Evaluate(p, {0}, &value, nullptr)) return false;
      *cost = value(0);
    }
    return std::isfinite(*cost);
  }
  int NumParameters() const override { return arms_ ? 6 : 5; }

 private:
  solvers::RolloutFunction* model_;
  bool arms_;
};

class FitTable : public ceres::IterationCallback {
 public:
  FitTable(FILE* log, const double* x, bool arms) : log_(log), x_(x), arms_(arms) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
    if (s.iteration == 0) {
      std::fprintf(log_, "%4s %13s %11s %11s %9s %14s %14s %9s %9s %9s", "iter", "loss", "loss_change", "|gradient|",
                   "total_t", "youngs_modulus", "poissons_ratio", "slack_mm", "lag_s", "length_mm");
      std::fprintf(log_, arms_ ? " %14s\n" : "\n", "arms_youngs_modulus");
    }
    std::fprintf(log_, "%4d %13.6e %11.3e %11.3e %9.2f %14.6g %14.6g %9.4f %9.4f %9.3f", s.iteration, s.cost,
                 s.cost_change, s.gradient_max_norm, s.cumulative_time_in_seconds, x_[0], x_[1], x_[2] / kMm, x_[3],
                 x_[4] / kMm);
    if (arms_) std::fprintf(log_, " %14.6g", x_[5]);
    std::fprintf(log_, "\n");
    std::fflush(log_);
    return ceres::SOLVER_CONTINUE;
  }

 private:
  FILE* log_;
  const double* x_;
  bool arms_;
};

// The iteration table of the least-squares fit (values in the blocks;
// `water` nullptr when the water is not fitted).
class LeastSquaresTable : public ceres::IterationCallback {
 public:
  LeastSquaresTable(FILE* log, const double* material, const double* actuation, bool release, const double* water,
                    bool density, const double* damping)
      : log_(log),
        material_(material),
        actuation_(actuation),
        release_(release),
        water_(water),
        density_(density),
        damping_(damping) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
    if (s.iteration == 0) {
      std::fprintf(log_, "%4s %13s %11s %11s %9s %14s %14s %9s %9s %9s", "iter", "cost", "cost_change", "|gradient|",
                   "total_t", "youngs_modulus", "poissons_ratio", "slack_mm", "lag_s", "length_mm");
      if (release_) std::fprintf(log_, " %9s", "release_s");
      if (water_) std::fprintf(log_, " %9s %9s %9s", "drag_t", "drag_n", "thrust");
      if (density_) std::fprintf(log_, " %9s", "density");
      if (damping_) std::fprintf(log_, " %9s", "damping");
      std::fprintf(log_, "\n");
    }
    std::fprintf(log_, "%4d %13.6e %11.3e %11.3e %9.2f %14.6g %14.6g %9.4f %9.4f %9.3f", s.iteration, s.cost,
                 s.cost_change, s.gradient_max_norm, s.cumulative_time_in_seconds, material_[0], material_[1],
                 actuation_[0] / kMm, actuation_[1], actuation_[2] / kMm);
    if (release_) std::fprintf(log_, " %9.4f", actuation_[3]);
    if (water_) std::fprintf(log_, " %9.4f %9.4f %9.4f", water_[0], water_[1], water_[2]);
    if (density_) std::fprintf(log_, " %9.2f", material_[2]);
    if (damping_) std::fprintf(log_, " %9.4f", damping_[0]);
    std::fprintf(log_, "\n");
    std::fflush(log_);
    return ceres::SOLVER_CONTINUE;
  }

 private:
  FILE* log_;
  const double* material_;
  const double* actuation_;
  bool release_;
  const double* water_;
  bool density_;
  const double* damping_;
};

// The tangent coordinate of x under `map` (0 for linear and log maps).
double BoundCoordinate(const solvers::CoordinateMap& map, double x) {
  if (map.kind == solvers::CoordinateMap::Kind::kLogit) {
    return std::log((x - map.lower) / (map.upper - x));
  }
  if (map.kind == solvers::CoordinateMap::Kind::kLogLogit) {
    const double s = std::log(x / map.lower) / std::log(map.upper / map.lower);
    return std::log(s / (1 - s));
  }
  return 0;
}

}  // namespace

const char* ToString(StarfishFitMethod method) {
  switch (method) {
    case StarfishFitMethod::kLbfgs:
      return "lbfgs";
    case StarfishFitMethod::kLevenbergMarquardt:
      return "lm";
  }
  return "unknown";
}

StarfishFitMethod ParseStarfishFitMethod(const std::string& name) {
  if (name == "lbfgs") return StarfishFitMethod::kLbfgs;
  if (name == "lm") return StarfishFitMethod::kLevenbergMarquardt;
  throw InvalidInputError("--fit = '" + name + "' is invalid: calibrate-starfish fits with 'lm' or 'lbfgs'");
}

std::vector<solvers::CoordinateMap> StarfishFitCoordinates(bool arms) {
  using solvers::CoordinateMap;
  std::vector<CoordinateMap> maps = {CoordinateMap::LogLogit(kMinE, kMaxE), CoordinateMap::LogLogit(kMinNu, kMaxNu),
                                     CoordinateMap::Logit(0, kMaxSlack), CoordinateMap::LogLogit(kMinLag, kMaxLag),
                                     CoordinateMap::LogLogit(kMinLength, kMaxLength)};
  if (arms) maps.push_back(CoordinateMap::LogLogit(kMinE, kMaxE));
  return maps;
}

std::vector<solvers::CoordinateMap> StarfishWaterCoordinates() {
  using solvers::CoordinateMap;
  return {CoordinateMap::LogLogit(kMinDragTangential, kMaxDragTangential),
          CoordinateMap::LogLogit(kMinDragNormal, kMaxDragNormal), CoordinateMap::LogLogit(kMinThrust, kMaxThrust)};
}

void CheckStarfishWaterStart(const StarfishWater& w) {
  if (!(w.drag_tangential > kMinDragTangential && w.drag_tangential < kMaxDragTangential))
    throw InvalidInputError("drag_tangential = " + Num(w.drag_tangential) + " is outside the fit's interval (" +
                            Num(kMinDragTangential) + ", " + Num(kMaxDragTangential) + ")");
  if (!(w.drag_normal > kMinDragNormal && w.drag_normal < kMaxDragNormal))
    throw InvalidInputError("drag_normal = " + Num(w.drag_normal) + " is outside the fit's interval (" +
                            Num(kMinDragNormal) + ", " + Num(kMaxDragNormal) + ")");
  if (!(w.thrust > kMinThrust && w.thrust < kMaxThrust))
    throw InvalidInputError("thrust = " + Num(w.thrust) + " is outside the fit's interval (" + Num(kMinThrust) + ", " +
                            Num(kMaxThrust) + ")");
}

void CheckStarfishMassDampingStart(double density, const StarfishMassDamping& md) {
  if (md.fit_density && !(density > kMinDensity && density < kMaxDensity))
    throw InvalidInputError("density = " + Num(density) + " is outside the fit's interval (" + Num(kMinDensity) + ", " +
                            Num(kMaxDensity) + ") kg/m^3");
  if (md.linear_damping_guess && !(*md.linear_damping_guess > kMinDamping && *md.linear_damping_guess < kMaxDamping))
    throw InvalidInputError("linear_damping = " + Num(*md.linear_damping_guess) + " is outside the fit's interval (" +
                            Num(kMinDamping) + ", " + Num(kMaxDamping) + ") 1/s");
}

std::vector<double> StarfishFitStart(const MaterialParameters& m, const StarfishActuation& a, bool arms) {
  if (!(m.youngs_modulus > kMinE && m.youngs_modulus < kMaxE))
    throw InvalidInputError("youngs_modulus = " + Num(m.youngs_modulus) +
                            " is outside the fit's interval (1e4, 5e6) Pa");
  if (!(m.poissons_ratio > kMinNu && m.poissons_ratio < kMaxNu))
    throw InvalidInputError("poissons_ratio = " + Num(m.poissons_ratio) + " is outside the fit's interval (0.2, 0.45)");
  if (!(a.slack > 0 && a.slack < kMaxSlack))
    throw InvalidInputError("tendon slack = " + Num(a.slack) + " is outside the fit's interval (0, 0.015) m");
  if (!(a.lag > kMinLag && a.lag < kMaxLag))
    throw InvalidInputError("tendon lag = " + Num(a.lag) + " is outside the fit's interval (0.001, 0.5) s");
  if (!(a.length > kMinLength && a.length < kMaxLength))
    throw InvalidInputError("tendon length = " + Num(a.length) + " is outside the fit's interval (0.03, 0.13) m");
  std::vector<double> x = {m.youngs_modulus, m.poissons_ratio, a.slack, a.lag, a.length};
  if (arms) x.push_back(m.youngs_modulus);
  return x;
}

StarfishFit FitStarfishLoss(solvers::RolloutFunction* model, bool arms, const MaterialParameters& guess,
                            const StarfishActuation& actuation_guess, int max_iterations, FILE* log) {
  std::vector<double> x = StarfishFitStart(guess, actuation_guess, arms);
  ceres::GradientProblem problem(new StarfishLoss(model, arms),
                                 new solvers::CoordinateManifold(StarfishFitCoordinates(arms)));
  ceres::GradientProblemSolver::Options options;
  options.line_search_direction_type = ceres::LBFGS;
  // Scale L-BFGS' initial inverse Hessian by the observed curvature: the
  // first step is the gradient's length, the later ones Newton-like.
  options.use_approximate_eigenvalue_bfgs_scaling = true;
  options.max_num_iterations = max_iterations;
  options.function_tolerance = 1e-5;
  options.gradient_tolerance = 1e-8;
  options.parameter_tolerance = 1e-5;
  options.logging_type = ceres::SILENT;
  options.update_state_every_iteration = true;
  FitTable table(log, x.data(), arms);
  if (log) options.callbacks.push_back(&table);
  ceres::GradientProblemSolver::Summary summary;
  ceres::Solve(options, problem, x.data(), &summary);
  StarfishFit fit;
  fit.material = MaterialParameters{x[0], x[1], guess.density};
  fit.actuation = StarfishActuation{x[2], x[3], x[4]};
  if (arms) fit.region_materials = {MaterialParameters{x[5], x[1], guess.density}};
  fit.initial_cost = summary.initial_cost;
  fit.final_cost = summary.final_cost;
  fit.iterations = static_cast<int>(summary.iterations.size()) - 1;
  fit.usable = summary.IsSolutionUsable() && std::isfinite(summary.final_cost);
  fit.termination = summary.message;
  fit.statistics = model->statistics();
  return fit;
}

std::vector<std::string> StarfishFitNames(bool release, bool water, bool density, bool damping) {
  std::vector<std::string> names = {"youngs_modulus", "poissons_ratio"};
  if (density) names.push_back("density");
  for (const char* n : {"tendon_slack", "tendon_lag", "tendon_length"}) names.push_back(n);
  if (release) names.push_back("tendon_release_lag");
  if (water)
    for (const char* n : {"drag_tangential", "drag_normal", "thrust"}) names.push_back(n);
  if (damping) names.push_back("linear_damping");
  return names;
}

std::vector<double> StarfishFitValues(const StarfishFit& fit) {
  std::vector<double> v = {fit.material.youngs_modulus, fit.material.poissons_ratio};
  if (fit.density_fitted) v.push_back(fit.material.density);
  for (double a : {fit.actuation.slack, fit.actuation.lag, fit.actuation.length}) v.push_back(a);
  if (fit.actuation.release_lag) v.push_back(*fit.actuation.release_lag);
  if (fit.water_fitted)
    for (double w : {fit.water.drag_tangential, fit.water.drag_normal, fit.water.thrust}) v.push_back(w);
  if (fit.linear_damping) v.push_back(*fit.linear_damping);
  return v;
}

StarfishFit FitStarfishLeastSquares(solvers::RolloutFunction* model, int residual_functional,
                                    const MaterialParameters& guess, const StarfishActuation& actuation_guess,
                                    const StarfishWater* water_guess, int max_iterations, FILE* log,
                                    const StarfishMassDamping& mass_damping) {
  const std::vector<double> start = StarfishFitStart(guess, actuation_guess, false);
  if (water_guess) CheckStarfishWaterStart(*water_guess);
  CheckStarfishMassDampingStart(guess.density, mass_damping);
  const bool density = mass_damping.fit_density;
  const bool damping = mass_damping.linear_damping_guess.has_value();
  const bool release = actuation_guess.release_lag.has_value();
  if (release && !(*actuation_guess.release_lag > kMinLag && *actuation_guess.release_lag < kMaxLag))
    throw InvalidInputError("tendon release_lag = " + Num(*actuation_guess.release_lag) +
                            " is outside the fit's interval (0.001, 0.5) s");
  // The maps in the blocks' order (material, actuation, water, damping).
  const std::vector<solvers::CoordinateMap> fit_maps = StarfishFitCoordinates(false);
  std::vector<solvers::CoordinateMap> maps = {fit_maps[0], fit_maps[1]};
  if (density) maps.push_back(solvers::CoordinateMap::LogLogit(kMinDensity, kMaxDensity));
  for (int i = 2; i < 5; ++i) maps.push_back(fit_maps[i]);
  if (release) maps.push_back(solvers::CoordinateMap::LogLogit(kMinLag, kMaxLag));
  double material[3] = {start[0], start[1], guess.density};
  double actuation[4] = {start[2], start[3], start[4], release ? *actuation_guess.release_lag : 0};
  double water[3] = {0, 0, 0};
  double damping_value[1] = {damping ? *mass_damping.linear_damping_guess : 0};
  std::vector<double*> blocks = {material, actuation};
  std::vector<int> sizes = {density ? 3 : 2, release ? 4 : 3};
  if (water_guess) {
    water[0] = water_guess->drag_tangential;
    water[1] = water_guess->drag_normal;
    water[2] = water_guess->thrust;
    blocks.push_back(water);
    sizes.push_back(3);
    for (const solvers::CoordinateMap& m : StarfishWaterCoordinates()) maps.push_back(m);
  }
  if (damping) {
    blocks.push_back(damping_value);
    sizes.push_back(1);
    maps.push_back(solvers::CoordinateMap::LogLogit(kMinDamping, kMaxDamping));
  }
  const int n = static_cast<int>(maps.size());
  solvers::RolloutEvaluationCallback callback(model, blocks);
  ceres::Problem::Options problem_options;
  problem_options.evaluation_callback = &callback;
  ceres::Problem problem(problem_options);
  solvers::AddMarkerResidualBlocks(&problem, model, residual_functional, blocks);
  for (size_t b = 0, first = 0; b < blocks.size(); first += sizes[b], ++b)
    problem.SetManifold(blocks[b], new solvers::CoordinateManifold(std::vector<solvers::CoordinateMap>(
                                       maps.begin() + first, maps.begin() + first + sizes[b])));

  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  // The marker error is far from quadratic over Ceres' default first trust
  // region (1e4): start with steps of order 1 in the tangent coordinates.
  options.initial_trust_region_radius = 1;
  options.max_num_iterations = max_iterations;
  options.function_tolerance = 1e-6;
  options.parameter_tolerance = 1e-6;
  options.gradient_tolerance = 1e-12;
  options.update_state_every_iteration = true;
  options.logging_type = ceres::SILENT;
  LeastSquaresTable table(log, material, actuation, release, water_guess ? water : nullptr, density,
                          damping ? damping_value : nullptr);
  if (log) options.callbacks.push_back(&table);
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);

  StarfishFit fit;
  fit.material = MaterialParameters{material[0], material[1], density ? material[2] : guess.density};
  fit.density_fitted = density;
  fit.actuation = StarfishActuation{actuation[0], actuation[1], actuation[2]};
  if (release) fit.actuation.release_lag = actuation[3];
  if (water_guess) {
    fit.water = StarfishWater{water[0], water[1], water[2]};
    fit.water_fitted = true;
  }
  if (damping) fit.linear_damping = damping_value[0];
  fit.initial_cost = summary.initial_cost;
  fit.final_cost = summary.final_cost;
  fit.iterations = static_cast<int>(summary.iterations.size()) - 1;
  fit.usable = summary.IsSolutionUsable() && summary.termination_type != ceres::FAILURE;
  fit.termination = summary.message;
  if (!std::isfinite(summary.final_cost)) {  // Ceres "converges" on a cost that stays inf
    fit.usable = false;
    fit.termination += "; the cost is not finite";
  }

  // Rows with a weight (the markers' unobserved y has none).
  VectorXd r;
  const std::vector<double> values = StarfishFitValues(fit);
  const VectorXd point = Eigen::Map<const VectorXd>(values.data(), n);
  const std::vector<int> rows = model->RowsOf(residual_functional);
  if (fit.usable && model->Evaluate(point, rows, &r, nullptr)) {
    MatrixXd j;
    model->Evaluate(point, rows, nullptr, &j);
    int used = 0;
    for (int i = 0; i < j.rows(); ++i) used += j.row(i).squaredNorm() > 0 || r(i) != 0;
    fit.residuals = used;
    const double noise = r.squaredNorm() / std::max(1, used - n);
    ceres::Covariance::Options covariance_options;
    covariance_options.algorithm_type = ceres::DENSE_SVD;
    covariance_options.null_space_rank = -1;
    ceres::Covariance covariance(covariance_options);
    std::vector<std::pair<const double*, const double*>> pairs;
    for (size_t a = 0; a < blocks.size(); ++a)
      for (size_t b = a; b < blocks.size(); ++b) pairs.emplace_back(blocks[a], blocks[b]);
    if (covariance.Compute(pairs, &problem)) {
      MatrixXd c(n, n);
      for (size_t a = 0, fa = 0; a < blocks.size(); fa += sizes[a], ++a)
        for (size_t b = a, fb = fa; b < blocks.size(); fb += sizes[b], ++b) {
          std::vector<double> block(sizes[a] * sizes[b]);
          covariance.GetCovarianceBlock(blocks[a], blocks[b], block.data());
          for (int u = 0; u < sizes[a]; ++u)
            for (int v = 0; v < sizes[b]; ++v) c(fa + u, fb + v) = c(fb + v, fa + u) = block[sizes[b] * u + v];
        }
      c *= noise;
      for (int a = 0; a < n; ++a) fit.standard_deviation.push_back(std::sqrt(std::max(0.0, c(a, a))));
      for (int a = 0; a < n; ++a)
        for (int b = 0; b < n; ++b) {
          const double d = fit.standard_deviation[a] * fit.standard_deviation[b];
          fit.correlation.push_back(d > 0 ? c(a, b) / d : 0.0);
        }
    }
    for (int a = 0; a < n; ++a) fit.at_bound.push_back(std::abs(BoundCoordinate(maps[a], point(a))) > 5);
  }
  fit.statistics = model->statistics();
  return fit;
}

}  // namespace diffpd::problems
