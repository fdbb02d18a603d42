#include "diffpd/strip_open_loop_controller.h"

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
  CheckStripDrives(drives_, delay_line_.num_strips(), channels, "StripOpenLoopController", "the channels");
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
  action->external_force.resize(0);
  delay_line_.Advance(memory, StripContractions(drives_, ChannelValues(step)), next_memory, &action->activation);
}

void StripOpenLoopController::ActVjp(int step, const State& state, const VectorXd& memory,
                                     const ControlAction& g_action, const VectorXd& g_next_memory, VectorXd* gx,
                                     VectorXd* gv, VectorXd* g_memory, VectorXd* g_parameters) const {
  const VectorXd w = ChannelValues(step);
  VectorXd g_u;
  delay_line_.AdvanceVjp(g_action.activation, g_next_memory, g_memory, &g_u);
  VectorXd g_w = VectorXd::Zero(channels_);
  AddStripContractionsVjp(drives_, w, g_u, &g_w);
  // d tanh(theta) / d theta = 1 - w^2.
  g_parameters->segment(static_cast<Eigen::Index>(step) * channels_, channels_).array() +=
      g_w.array() * (1 - w.array().square());
}

}  // namespace diffpd
