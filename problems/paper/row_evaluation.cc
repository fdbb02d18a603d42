#include "paper/row_evaluation.h"

#include <chrono>
#include <ctime>

#include "diffpd/error.h"

namespace diffpd::problems {
namespace {

double Now(RowClock clock) {
  if (clock == RowClock::kWall)
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}

bool SameMaterial(const MaterialParameters& a, const MaterialParameters& b) {
  return a.youngs_modulus == b.youngs_modulus && a.poissons_ratio == b.poissons_ratio && a.density == b.density;
}

}  // namespace

RowEvaluation EvaluateRow(const PaperRow& row, Simulator* simulator, const VectorXd& x, bool gradient, RowClock clock) {
  if (row.prepare)
    throw InvalidInputError(row.name + ": the row needs its preparatory simulations first (PaperRow::Prepare)");
  const solvers::RolloutSetup setup = row.Setup(x);
  if (!SameMaterial(setup.material, simulator->scene().material)) simulator->SetMaterial(setup.material);
  RowEvaluation out;
  double start = Now(clock);
  // A closed-loop row (a controller block): the controller chooses every
  // step's action, for as many steps as the row has inputs.
  const Rollout rollout = setup.controller ? simulator->Simulate(setup.initial, *setup.controller, row.steps)
                                           : simulator->Simulate(setup.initial, setup.inputs);
  out.forward_s = Now(clock) - start;
  long iterations = 0;
  for (const StepReport& r : rollout.reports) {
    iterations += r.iterations;
    out.newton_fallback_steps += r.newton_fallback ? 1 : 0;
  }
  out.iterations_per_step = rollout.num_steps() > 0 ? double(iterations) / rollout.num_steps() : 0;
  LossGradient dl;
  out.loss = row.Loss(rollout, gradient ? &dl : nullptr);
  if (gradient) {
    start = Now(clock);
    const RolloutGradient g =
        setup.controller ? simulator->Backward(rollout, dl, *setup.controller) : simulator->Backward(rollout, dl);
    out.gradient = row.PullBack(x, g);
    out.backward_s = Now(clock) - start;
    out.backward_iterations_per_step =
        rollout.num_steps() > 0 ? double(g.report.linear_iterations) / rollout.num_steps() : 0;
    out.backward_fallbacks = g.report.fallbacks;
    out.backward_indefinite_steps = g.report.indefinite_steps;
  }
  return out;
}

std::vector<double> RandomDrawLosses(const PaperRow& row, Simulator* simulator) {
  std::vector<double> losses;
  for (const VectorXd& draw : row.random_draws) losses.push_back(EvaluateRow(row, simulator, draw, false).loss);
  return losses;
}

double NormalisedLoss(double loss, double random_mean, double baseline) {
  return (loss - baseline) / (random_mean - baseline);
}

}  // namespace diffpd::problems
