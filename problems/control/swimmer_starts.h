// Controller training over several initial states: one controller (the
// swimmer's network, the same weights) swims from `count` initial states and
// the training minimises the sum of the swim losses, L(theta) = sum_i L_i(theta),
// each start a term of a RolloutSet (diffpd/solvers/core/rollout_set.h,
// TermObjective::kSum) so that the same training runs in one process
// (LocalRolloutSet) or over MPI ranks (DistributedRolloutSet).
//
// Start i of n: every node at its rest position; start 0 at rest (the
// original problem), start i >= 1 moving as a rigid body with the lateral
// velocity speed * (cos a_i, sin a_i, 0), a_i = 2 pi (i - 1) / (n - 1), in
// the body's plane (m/s; the swimmer swims along +z and the loss penalises
// the lateral velocity, so the controller learns to recover from a push).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "control/swimmer_control.h"
#include "diffpd/solvers/core/rollout_set.h"

namespace diffpd::problems {

struct SwimmerStartsOptions {
  int count = 4;        // starts, >= 1
  double speed = 0.05;  // m/s, the starts' lateral speed, >= 0 and finite
  // Throws InvalidInputError: "starts = 0 is invalid: must be >= 1",
  // "start speed = -1 is invalid: must be finite and >= 0".
  void Validate() const;
};

// Start i's initial state (positions 3n, velocities 3n). Throws
// InvalidInputError for bad options or i outside [0, count) ("start 4 is out
// of range [0, 4)").
State SwimmerStartState(const Swimmer& swimmer, int i, const SwimmerStartsOptions& starts);

// Start i's term: MakeSwimmerFunction(swimmer, options, seed) from start i's
// state, its swim loss the one row. Throws as SwimmerStartState.
solvers::RolloutTerm SwimmerStartTerm(const Swimmer& swimmer, const SolverOptions& options, std::uint64_t seed, int i,
                                      const SwimmerStartsOptions& starts);

// Throws InvalidInputError unless this build has the optimiser's adapter
// ("optimizer 'ipopt' needs the Ipopt adapter, which this build lacks").
void CheckSetOptimizer(ControlOptimizer optimizer);

// A training over a set of starts (computing only; see TrainOverStarts).
struct MultiStartTraining {
  std::string optimizer;
  std::string optimizer_report;  // Ceres' brief report (L-BFGS), Ipopt's status; Adam: empty
  int starts = 0, parameters = 0, steps_per_start = 0;
  // One row per evaluation (reward = -L, the sum over the starts;
  // simulated_steps counts every start's steps) and a last one for the
  // final controller (no gradient).
  std::vector<TrainingEvaluation> history;
  int failed_evaluations = 0;
  VectorXd initial_parameters, final_parameters;
  // Each start's reward (-L_i) at the initial and at the final controller.
  std::vector<double> initial_start_rewards, final_start_rewards;
  double total_seconds = 0;  // wall time of the training and the final evaluation

  double initial_reward() const { return history.front().reward; }
  double final_reward() const { return history.back().reward; }
};

// Trains the set's controller from its initial parameters with
// settings.optimizer (Adam, L-BFGS or Ipopt; settings.seed is not read, the terms
// were made with theirs) within settings.evaluations evaluations of the
// whole set (each: every start's rollout and reverse pass). Call it on rank
// 0 of a distributed set. Throws InvalidInputError for bad settings or an
// optimiser CheckSetOptimizer refuses, SolverError when an Adam evaluation
// or the final one fails.
MultiStartTraining TrainOverStarts(solvers::RolloutSet* set, int steps_per_start, const TrainingSettings& settings);

}  // namespace diffpd::problems
