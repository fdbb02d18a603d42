// A budget of rollouts for an optimiser of a RolloutFunction's scalar loss,
// and the learning curve it records (and prints, a line per evaluation): every new parameter point is one
// evaluation (a closed-loop rollout, with or without its reverse pass); the
// optimiser may evaluate at most `budget` of them. Optimiser wrappers
// (Adam's loop, a ceres::FirstOrderFunction, an Ipopt TNLP) ask Admit
// before an evaluation and report it with Record after.
#pragma once

#include <cstdio>
#include <functional>
#include <vector>

#include "diffpd/solvers/core/rollout_function.h"
#include "diffpd/solvers/core/rollout_set.h"
#include "diffpd/types.h"

namespace diffpd::problems {

// One evaluation: the reward of the rollout at a parameter point, and what
// it cost.
struct TrainingEvaluation {
  int evaluation = 0;        // 0, 1, ...
  long simulated_steps = 0;  // steps simulated before this rollout (the learning curve's x)
  double reward = 0;         // -L
  double forward_seconds = 0;
  double backward_seconds = 0;  // 0 where no gradient was computed
  double gradient_norm = 0;     // |dL/dtheta| (0 where no gradient was computed)
};

class EvaluationBudget {
 public:
  // `function` (not owned) must outlive the budget; rollouts of
  // steps_per_rollout steps; a line per evaluation into `log` (nullptr:
  // silent; not owned). Throws InvalidInputError for budget < 1
  // ("evaluations = 0 is invalid: must be >= 1").
  EvaluationBudget(const solvers::RolloutFunction* function, int budget, int steps_per_rollout, FILE* log);
  // The same over a rollout set's scalar loss (`set` not owned, outliving
  // the budget): steps_per_rollout counts every term's steps, the timings are
  // those of the terms evaluated in this process (RolloutSet::statistics).
  EvaluationBudget(const solvers::RolloutSet* set, int budget, int steps_per_rollout, FILE* log);

  // Whether p may be evaluated: always at the latest point, at a new point
  // while fewer than `budget` evaluations were made (otherwise the budget is
  // exhausted from then on).
  bool Admit(const Eigen::Ref<const VectorXd>& p);
  // After an admitted evaluation at p (ok: it succeeded) of the loss and,
  // if gradient is not nullptr, its gradient: a new point adds a row to the
  // history (a failed one counts against the budget without a row); the
  // latest point gains the gradient's norm and the backward time.
  void Record(const Eigen::Ref<const VectorXd>& p, bool ok, double loss, const VectorXd* gradient);

  // Prints the latest row if it is still waiting for its gradient (call
  // once the optimiser is done).
  void Finish();

  int used() const { return used_; }
  int budget() const { return budget_; }
  bool exhausted() const { return exhausted_; }
  int failed() const { return failed_; }
  const std::vector<TrainingEvaluation>& history() const { return history_; }

 private:
  void Print(const TrainingEvaluation& row) const;

  std::function<solvers::RolloutStatistics()> statistics_;  // the timings' source
  int budget_, steps_;
  FILE* log_;
  int used_ = 0, failed_ = 0;
  bool exhausted_ = false;
  VectorXd latest_;
  bool latest_recorded_ = false;
  bool pending_print_ = false;  // the latest row is printed once its gradient comes, or at the next point
  double seen_forward_ = 0, seen_backward_ = 0;  // the function's timings at the last Record
  std::vector<TrainingEvaluation> history_;
};

}  // namespace diffpd::problems
