// Simulator::SimulateCheckpointed and Backward over a checkpointed rollout.
#include "diffpd/checkpointed_rollout.h"

#include <algorithm>
#include <chrono>
#include <sstream>

#include "diffpd/error.h"
#include "diffpd/simulator.h"
#include "solver/adjoint_sweep.h"
#include "solver/checkpoint_schedule.h"
#include "solver/forward_options_scope.h"
#include "solver/rollout_checks.h"
#include "solver/simulator_impl.h"

namespace diffpd {

void CheckpointOptions::Validate() const {
  if (num_checkpoints < 1) {
    std::ostringstream msg;
    msg << "checkpoint options: num_checkpoints = " << num_checkpoints << " is invalid: must be >= 1";
    throw InvalidInputError(msg.str());
  }
}

long CheckpointedRollout::stored_state_bytes() const {
  long doubles = initial.x.size() + initial.v.size() + final.x.size() + final.v.size();
  for (const State& s : checkpoints) doubles += s.x.size() + s.v.size();
  return doubles * static_cast<long>(sizeof(double));
}

namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

CheckpointedRollout Simulator::SimulateCheckpointed(const State& initial, const std::vector<StepInput>& inputs,
                                                    const CheckpointOptions& checkpoints,
                                                    const std::function<void(int k, const State& state)>& observer) {
  checkpoints.Validate();
  CheckpointedRollout r;
  r.material = impl_->scene.material;
  for (const MaterialRegion& region : impl_->scene.material_regions) r.region_materials.push_back(region.material);
  // Cold SVDs: a recomputed step repeats the forward's bit for bit.
  r.options = impl_->options;
  r.options.svd_warm_start = false;
  r.checkpoint_options = checkpoints;
  r.inputs = inputs;
  r.initial = initial;
  const int steps = static_cast<int>(inputs.size());
  r.checkpoint_steps = internal::FirstDescentSteps(steps, checkpoints.num_checkpoints);
  r.checkpoints.reserve(r.checkpoint_steps.size());
  r.checkpoint_reports.reserve(r.checkpoint_steps.size());
  const internal::ForwardOptionsScope forward(*impl_, r.options);
  State state = initial;
  if (observer) observer(0, state);
  size_t next = 0;
  for (int k = 0; k < steps; ++k) {
    StepReport report;
    state = Step(state, inputs[k], &report);
    r.forward_seconds += report.seconds;
    r.forward_iterations += report.iterations;
    if (next < r.checkpoint_steps.size() && r.checkpoint_steps[next] == k + 1) {
      r.checkpoints.push_back(state);
      r.checkpoint_reports.push_back(report);
      ++next;
    }
    if (k + 1 == steps) r.final_report = report;
    if (observer) observer(k + 1, state);
  }
  r.final = std::move(state);
  return r;
}

RolloutGradient Simulator::Backward(const CheckpointedRollout& rollout, const LossGradient& loss) {
  internal::CheckLossGradient(loss, rollout.num_steps(), impl_->num_dofs());
  StateLossGradient state_loss;
  state_loss.state_gradient = [&loss](int k, const State&, VectorXd* dx, VectorXd* dv) {
    *dx = loss.dx[k];
    *dv = loss.dv[k];
  };
  return Backward(rollout, state_loss);
}

RolloutGradient Simulator::Backward(const CheckpointedRollout& rollout, const StateLossGradient& loss) {
  internal::SimulatorImpl& sim = *impl_;
  const auto start = Clock::now();
  const int n = sim.num_dofs();
  const int steps = rollout.num_steps();
  internal::CheckCheckpointedRollout(sim, rollout, "Backward");

  auto state_gradient = [&loss, n](int k, const State& s, VectorXd* dx, VectorXd* dv) {
    dx->resize(0);
    dv->resize(0);
    if (!loss.state_gradient) return;
    loss.state_gradient(k, s, dx, dv);
    for (const VectorXd* g : {dx, dv})
      if (g->size() != 0 && (g->size() != n || !g->allFinite())) {
        std::ostringstream msg;
        msg << "Backward: the loss's " << (g == dx ? "dL/dx_" : "dL/dv_") << k << " has " << g->size()
            << " entries, expected 0 or " << n << " finite ones (3 x number of nodes)";
        throw InvalidInputError(msg.str());
      }
  };
  VectorXd dx, dv;
  state_gradient(steps, rollout.final, &dx, &dv);
  const bool keep = !loss.step_gradient;
  internal::AdjointSweep sweep(sim, steps, rollout.options, dx, dv, nullptr, keep);
  int recomputed = 0;
  // States held now and at most: the rollout's, the working checkpoints,
  // the state after the step being differentiated and the one advancing.
  const int kept = 2 + static_cast<int>(rollout.checkpoints.size());
  int held = kept, peak = kept;
  auto hold = [&held, &peak](int count) {
    held += count;
    peak = std::max(peak, held);
  };
  // A state j > 0 with the report of step j - 1 (frictional contact's active
  // set and the residuals the adjoint tolerance follows).
  struct Reached {
    State state;
    StepReport report;
  };
  // Advances `count` >= 1 steps from state `first`.
  auto advance = [&](const State& from, int first, int count) {
    Reached r{from, StepReport()};
    hold(2);
    const internal::ForwardOptionsScope forward(sim, rollout.options);
    for (int k = first; k < first + count; ++k) r.state = Step(r.state, rollout.inputs[k], &r.report);
    recomputed += count;
    hold(-1);
    return r;
  };
  // The state after the step being differentiated next, and its report.
  Reached after{rollout.final, rollout.final_report};
  hold(1);
  // Reverses steps [a, a + l) from state a (report: of step a - 1, nullptr
  // for a = 0) with `slots` free checkpoint slots; `after` holds state a + l.
  std::function<void(int, int, int, const State&, const StepReport*)> reverse =
      [&](int a, int l, int slots, const State& state_a, const StepReport* report_a) {
        while (l > 1) {
          const int m = internal::BinomialSplit(l, slots);
          const auto it = std::lower_bound(rollout.checkpoint_steps.begin(), rollout.checkpoint_steps.end(), a + m);
          if (it != rollout.checkpoint_steps.end() && *it == a + m) {
            const size_t c = it - rollout.checkpoint_steps.begin();
            reverse(a + m, l - m, slots - 1, rollout.checkpoints[c], &rollout.checkpoint_reports[c]);
          } else {
            const Reached reached = advance(state_a, a, m);
            reverse(a + m, l - m, slots - 1, reached.state, &reached.report);
            hold(-1);
          }
          l = m;
        }
        state_gradient(a, state_a, &dx, &dv);
        sweep.Step(a, state_a, after.state, rollout.inputs[a], &after.report, nullptr, dx, dv);
        if (!keep) loss.step_gradient(a, sweep.step_external_force(), sweep.step_activation());
        after.state = state_a;
        after.report = report_a ? *report_a : StepReport();
      };
  // Without steps the final state is the initial one, its dL/dx asked for above.
  if (steps > 0) reverse(0, steps, rollout.checkpoint_options.num_checkpoints, rollout.initial, nullptr);
  RolloutGradient out;
  try {
    out = sweep.Finish();
  } catch (const SolverError& e) {
    if (e.status() != SolverStatus::kNonFinite) throw;
    throw SolverError(SolverStatus::kNonFinite, std::string(ToString(sim.options.method)) +
                                                    " backward: the adjoint overflowed double precision (" + e.what() +
                                                    ")");
  }
  out.report.recomputed_steps = recomputed;
  out.report.peak_states = peak;
  out.report.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return out;
}

}  // namespace diffpd
