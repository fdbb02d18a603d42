#include "control/swimmer_starts.h"

#include <chrono>
#include <cmath>
#include <sstream>

#include "control/swimmer_optimizers.h"
#include "diffpd/error.h"

namespace diffpd::problems {
namespace {

using Clock = std::chrono::steady_clock;
constexpr double kPi = 3.14159265358979323846;

double Seconds(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// Each term's reward (-sum of its rows) at p; false on failure.
bool StartRewards(solvers::RolloutSet* set, const VectorXd& p, std::vector<double>* rewards) {
  VectorXd v;
  if (!set->Evaluate(p, &v, nullptr)) return false;
  rewards->clear();
  int offset = 0;
  for (int t = 0; t < set->num_terms(); ++t) {
    const int rows = set->term_rows(t);
    rewards->push_back(-v.segment(offset, rows).sum());
    offset += rows;
  }
  return true;
}

}  // namespace

void SwimmerStartsOptions::Validate() const {
  if (count < 1) {
    std::ostringstream msg;
    msg << "starts = " << count << " is invalid: must be >= 1";
    throw InvalidInputError(msg.str());
  }
  if (!std::isfinite(speed) || speed < 0) {
    std::ostringstream msg;
    msg << "start speed = " << speed << " is invalid: must be finite and >= 0";
    throw InvalidInputError(msg.str());
  }
}

State SwimmerStartState(const Swimmer& swimmer, int i, const SwimmerStartsOptions& starts) {
  starts.Validate();
  if (i < 0 || i >= starts.count) {
    std::ostringstream msg;
    msg << "start " << i << " is out of range [0, " << starts.count << ")";
    throw InvalidInputError(msg.str());
  }
  const Mesh& mesh = swimmer.scene.mesh;
  State state;
  state.x = Eigen::Map<const VectorXd>(mesh.vertices.data(), mesh.vertices.size());
  state.v = VectorXd::Zero(state.x.size());
  if (i > 0) {
    const double angle = 2 * kPi * (i - 1) / (starts.count - 1);
    const Vec3 velocity(starts.speed * std::cos(angle), starts.speed * std::sin(angle), 0);
    for (int node = 0; node < mesh.num_vertices(); ++node) state.v.segment<3>(3 * node) = velocity;
  }
  return state;
}

solvers::RolloutTerm SwimmerStartTerm(const Swimmer& swimmer, const SolverOptions& options, std::uint64_t seed, int i,
                                      const SwimmerStartsOptions& starts) {
  const State initial = SwimmerStartState(swimmer, i, starts);
  solvers::RolloutTerm term;
  term.function = MakeSwimmerFunction(swimmer, options, seed);
  term.function->SetInitialState(initial);
  term.rows = term.function->RowsOf(0);
  return term;
}

void CheckSetOptimizer(ControlOptimizer optimizer) {
  if (!ControlOptimizerAvailable(optimizer))
    throw InvalidInputError(std::string("optimizer '") + ToString(optimizer) + "' needs the " +
                            (optimizer == ControlOptimizer::kLbfgs ? "Ceres" : "Ipopt") +
                            " adapter, which this build lacks");
}

MultiStartTraining TrainOverStarts(solvers::RolloutSet* set, int steps_per_start, const TrainingSettings& settings) {
  CheckSetOptimizer(settings.optimizer);
  settings.adam.Validate();
  MultiStartTraining result;
  result.optimizer = ToString(settings.optimizer);
  result.starts = set->num_terms();
  result.parameters = set->num_parameters();
  result.steps_per_start = steps_per_start;
  result.initial_parameters = set->initial_parameters();
  EvaluationBudget budget(set, settings.evaluations, steps_per_start * set->num_terms(), settings.log);
  const auto start = Clock::now();
  // The initial rollouts (the optimiser's first evaluation finds them cached
  // and the budget counts their time as its first row's forward time).
  if (!StartRewards(set, result.initial_parameters, &result.initial_start_rewards))
    throw SolverError(SolverStatus::kNonFinite, "the initial controller's rollouts: " + set->last_error());
  switch (settings.optimizer) {
    case ControlOptimizer::kAdam:
      result.final_parameters = MinimizeWithAdam(set, settings.adam, &budget);
      break;
    case ControlOptimizer::kLbfgs:
#if DIFFPD_WITH_CERES
      result.final_parameters = MinimizeWithLbfgs(set, &budget, &result.optimizer_report);
#endif
      break;
    case ControlOptimizer::kIpopt:
#if DIFFPD_WITH_IPOPT
      result.final_parameters = MinimizeWithIpopt(set, &budget, &result.optimizer_report);
#endif
      break;
  }
  budget.Finish();
  result.history = budget.history();
  result.failed_evaluations = budget.failed();
  TrainingEvaluation last;
  last.evaluation = static_cast<int>(result.history.size());
  last.simulated_steps = static_cast<long>(budget.used()) * steps_per_start * set->num_terms();
  const auto t0 = Clock::now();
  if (!StartRewards(set, result.final_parameters, &result.final_start_rewards))
    throw SolverError(SolverStatus::kNonFinite, "the final controller's rollouts: " + set->last_error());
  last.forward_seconds = Seconds(t0);
  last.reward = 0;
  for (double r : result.final_start_rewards) last.reward += r;
  if (settings.log)
    std::fprintf(settings.log, "%5d %9ld %14.6f %10.3f %10.3f %12s\n", last.evaluation, last.simulated_steps,
                 last.reward, last.forward_seconds, 0.0, "final");
  result.history.push_back(last);
  result.total_seconds = Seconds(start);
  return result;
}

}  // namespace diffpd::problems
