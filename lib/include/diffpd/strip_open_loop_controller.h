// An open-loop controller of muscle strips (controller.h), after the
// original DiffPD swimmers' open-loop controller: a free value per step and
// channel instead of a network, with the same strip drive and delay line as
// StripNetworkController (strip_network_controller.h). It ignores the state.
//
// Parameters theta (steps x channels values, step-major: theta[k * C + c]);
// at step k the channel values are
//
//   w_{k,c} = tanh(theta[k * C + c])  in (-1, 1),
//
// strip s driven by channel c_s with sign sigma_s contracts by
// u_s = max(sigma_s w_{k,c_s}, 0) (derivative 0 where sigma_s w = 0), and the
// delay line (muscle_strip.h) carries the contractions from root to tip.
// The memory is the delay line's (contractions, zero at the start).
#pragma once

#include <memory>
#include <vector>

#include "diffpd/controller.h"
#include "diffpd/muscle_strip.h"
#include "diffpd/strip_drive.h"

namespace diffpd {

class StripOpenLoopController : public Controller {
 public:
  // steps >= 1 and channels >= 1; drives: one per strip of the delay line,
  // each channel in [0, channels) and sign +1 or -1. The parameters start at
  // 0 (w = 0: no contraction). Throws InvalidInputError, e.g.
  // "StripOpenLoopController: steps = 0 is invalid: must be >= 1",
  // "StripOpenLoopController: 3 strip drives given, expected 2 (one per strip)",
  // "StripOpenLoopController: drives[1].channel = 4 is out of range [0, 4) (the channels)".
  StripOpenLoopController(int steps, int channels, MuscleDelayLine delay_line, std::vector<StripDrive> drives);

  int steps() const { return steps_; }
  int channels() const { return channels_; }
  const MuscleDelayLine& delay_line() const { return delay_line_; }
  // w_k (channels() values) of step k in [0, steps()).
  VectorXd ChannelValues(int step) const;

  std::unique_ptr<Controller> Clone() const override { return std::make_unique<StripOpenLoopController>(*this); }
  int num_parameters() const override { return static_cast<int>(theta_.size()); }
  VectorXd parameters() const override { return theta_; }
  // Throws InvalidInputError for a wrong size or a non-finite entry
  // ("StripOpenLoopController: parameters have 3 entries, expected 800").
  void SetParameters(const VectorXd& parameters) override;
  int memory_size() const override { return delay_line_.memory_size(); }
  // Throws InvalidInputError for a step outside [0, steps())
  // ("StripOpenLoopController: step 200 is out of range [0, 200) (the steps it has values for)").
  void Act(int step, const State& state, const VectorXd& memory, ControlAction* action,
           VectorXd* next_memory) const override;
  // Adds nothing to *gx and *gv (the controller ignores the state).
  void ActVjp(int step, const State& state, const VectorXd& memory, const ControlAction& g_action,
              const VectorXd& g_next_memory, VectorXd* gx, VectorXd* gv, VectorXd* g_memory,
              VectorXd* g_parameters) const override;

 private:
  void CheckStep(int step) const;

  int steps_, channels_;
  MuscleDelayLine delay_line_;
  std::vector<StripDrive> drives_;
  VectorXd theta_;
};

}  // namespace diffpd
