#include "calibration/starfish_recordings_fit.h"

#include <chrono>
#include <cmath>

#include <ceres/problem.h>
#include <ceres/solver.h>

#include "calibration/counting_cost_function.h"
#include "diffpd/error.h"
#include "diffpd/solvers/ceres/coordinate_manifold.h"

namespace diffpd::problems {
namespace {

constexpr double kMm = 1e-3;

// One line per iteration: cost, change, gradient, time and the 5 values.
class Table : public ceres::IterationCallback {
 public:
  Table(FILE* log, const double* x) : log_(log), x_(x) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
    if (s.iteration == 0)
      std::fprintf(log_, "%4s %13s %11s %11s %9s %14s %14s %9s %9s %9s\n", "iter", "cost", "cost_change", "|gradient|",
                   "total_t", "youngs_modulus", "poissons_ratio", "slack_mm", "lag_s", "length_mm");
    std::fprintf(log_, "%4d %13.6e %11.3e %11.3e %9.2f %14.6g %14.6g %9.4f %9.4f %9.3f\n", s.iteration, s.cost,
                 s.cost_change, s.gradient_max_norm, s.cumulative_time_in_seconds, x_[0], x_[1], x_[2] / kMm, x_[3],
                 x_[4] / kMm);
    std::fflush(log_);
    return ceres::SOLVER_CONTINUE;
  }

 private:
  FILE* log_;
  const double* x_;
};

// Each term's cost 1/2 |r_t|^2 at p (empty on failure).
std::vector<double> TermCosts(solvers::RolloutSet* set, const VectorXd& p) {
  VectorXd v;
  if (!set->Evaluate(p, &v, nullptr)) return {};
  std::vector<double> costs;
  int offset = 0;
  for (int t = 0; t < set->num_terms(); ++t) {
    costs.push_back(0.5 * v.segment(offset, set->term_rows(t)).squaredNorm());
    offset += set->term_rows(t);
  }
  return costs;
}

}  // namespace

solvers::RolloutTerm StarfishRecordingTerm(const StarfishCalibration& problem, const std::string& path,
                                           const SolverOptions& options, const StarfishRecordingsOptions& recordings) {
  if (problem.fit_method() != StarfishFitMethod::kLevenbergMarquardt || problem.regions() != StarfishRegions::kNone)
    throw InvalidInputError("the starfish recordings fit needs the lm fit and no material regions");
  StarfishFitStart(recordings.guess, recordings.actuation_guess, false);  // throws for a start outside the bounds
  const StarfishRecording recording = ReadStarfishRecording(path);
  const StarfishWindow window = MakeStarfishWindow(recording, recordings.start, recordings.seconds);
  solvers::RolloutTerm term;
  StarfishCalibration fixed_water = problem;  // the set's fit has the 5 parameters
  fixed_water.set_fit_water(false);
  fixed_water.set_fit_density(false);
  term.function = fixed_water.MakeModel(recording, window, options, recordings.guess, recordings.actuation_guess);
  term.rows = term.function->RowsOf(0);
  return term;
}

StarfishRecordingsFit FitStarfishOverSet(solvers::RolloutSet* set, double density, int max_iterations, FILE* log) {
  DIFFPD_CHECK(set->num_parameters() == 5, "the starfish recordings fit has 5 parameters");
  const VectorXd start = set->initial_parameters();
  double x[5] = {start(0), start(1), start(2), start(3), start(4)};
  StarfishRecordingsFit result;
  result.initial_costs = TermCosts(set, start);
  ceres::Problem problem;
  problem.AddResidualBlock(new CountingCostFunction(set, &result.evaluations), nullptr, x);
  problem.SetManifold(x, new solvers::CoordinateManifold(StarfishFitCoordinates(false)));

  // The single-recording fit's settings (FitStarfishLeastSquares).
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.initial_trust_region_radius = 1;
  options.max_num_iterations = max_iterations;
  options.function_tolerance = 1e-6;
  options.parameter_tolerance = 1e-6;
  options.gradient_tolerance = 1e-12;
  options.update_state_every_iteration = true;
  options.logging_type = ceres::SILENT;
  Table table(log, x);
  if (log) options.callbacks.push_back(&table);
  ceres::Solver::Summary summary;
  const auto begin = std::chrono::steady_clock::now();
  ceres::Solve(options, &problem, &summary);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();

  StarfishFit& fit = result.fit;
  fit.material = MaterialParameters{x[0], x[1], density};
  fit.actuation = StarfishActuation{x[2], x[3], x[4]};
  fit.initial_cost = summary.initial_cost;
  fit.final_cost = summary.final_cost;
  fit.iterations = static_cast<int>(summary.iterations.size()) - 1;
  fit.usable =
      summary.IsSolutionUsable() && summary.termination_type != ceres::FAILURE && std::isfinite(summary.final_cost);
  fit.termination = summary.message;
  if (!set->last_error().empty()) fit.termination += "; last failed evaluation: " + set->last_error();
  result.final_costs = TermCosts(set, Eigen::Map<const VectorXd>(x, 5));
  fit.statistics = set->statistics();
  return result;
}

}  // namespace diffpd::problems
