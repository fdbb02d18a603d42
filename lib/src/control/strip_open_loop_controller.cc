#include "diffpd/strip_open_loop_controller.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "diffpd/error.h"

namespace diffpd {
namespace {

[[noreturn]] void Invalid(const std::string& what) { throw InvalidInputError("StripOpenLoopController: " + what); }

}  // namespace

StripOpenLoopController::StripOpenLoopController(int steps, int channels, MuscleDelayLine delay_line,
                                                 std::vector<StripDrive> drives)
    : steps_(steps), channels_(channels), delay_line_(std::move(delay_line)), drives_(std::move(drives)) {
  std::ostringstream msg;
  if (steps < 1) {
    msg << "steps = " << steps << " is invalid: must be >= 1";
    Invalid(msg.str());
  }
  if (channels < 1) {
    msg << "channels = " << channels << " is invalid: must be >= 1";
    Invalid(msg.str());
  }
  if (static_cast<int>(drives_.size()) != delay_line_.num_strips()) {
    msg << drives_.size() << " strip drives given, expected " << delay_line_.num_strips() << " (one per strip)";
    Invalid(msg.str());
  }
  for (size_t s = 0; s < drives_.size(); ++s) {
    if (drives_[s].channel < 0 || drives_[s].channel >= channels) {
      msg << "drives[" << s << "].channel = " << drives_[s].channel << " is out of range [0, " << channels
          << ") (the channels)";
      Invalid(msg.str());
    }
    if (drives_[s].sign != 1 && drives_[s].sign != -1) {
      msg << "drives[" << s << "].sign = " << drives_[s].sign << " is invalid: must be +1 or -1";
      Invalid(msg.str());
    }
  }
  theta_ = VectorXd::Zero(static_cast<Eigen::Index>(steps) * channels);
}

void StripOpenLoopController::SetParameters(const VectorXd& parameters) {
  if (parameters.size() != theta_.size()) {
    std::ostringstream msg;
    msg << "parameters have " << parameters.size() << " entries, expected " << theta_.size();
    Invalid(msg.str());
  }
  if (!parameters.allFinite()) Invalid("parameters have a non-finite entry");
  theta_ = parameters;
}

void StripOpenLoopController::CheckStep(int step) const {
  if (step < 0 || step >= steps_) {
    std::ostringstream msg;
    msg << "step " << step << " is out of range [0, " << steps_ << ") (the steps it has values for)";
    Invalid(msg.str());
  }
}

VectorXd StripOpenLoopController::ChannelValues(int step) const {
  CheckStep(step);
  return theta_.segment(static_cast<Eigen::Index>(step) * channels_, channels_).array().tanh().matrix();
}

void StripOpenLoopController::Act(int step, const State& state, const VectorXd& memory, ControlAction* action,
                                  VectorXd* next_memory) const {
  const VectorXd w = ChannelValues(step);
  VectorXd u(drives_.size());
  for (size_t s = 0; s < drives_.size(); ++s) u(s) = std::max(drives_[s].sign * w(drives_[s].channel), 0.0);
  action->external_force.resize(0);
  delay_line_.Advance(memory, u, next_memory, &action->activation);
}

void StripOpenLoopController::ActVjp(int step, const State& state, const VectorXd& memory,
                                     const ControlAction& g_action, const VectorXd& g_next_memory, VectorXd* gx,
                                     VectorXd* gv, VectorXd* g_memory, VectorXd* g_parameters) const {
  const VectorXd w = ChannelValues(step);
  VectorXd g_u;
  delay_line_.AdvanceVjp(g_action.activation, g_next_memory, g_memory, &g_u);
  const Eigen::Index offset = static_cast<Eigen::Index>(step) * channels_;
  for (size_t s = 0; s < drives_.size(); ++s) {
    const int c = drives_[s].channel, sign = drives_[s].sign;
    // d tanh(theta) / d theta = 1 - w^2.
    if (sign * w(c) > 0) (*g_parameters)(offset + c) += sign * g_u(s) * (1 - w(c) * w(c));
  }
}

}  // namespace diffpd
