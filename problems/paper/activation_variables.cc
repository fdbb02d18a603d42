#include "paper/activation_variables.h"

#include <cmath>
#include <sstream>

#include "diffpd/error.h"

namespace diffpd::problems {
namespace {

void CheckMuscles(const std::vector<int>& muscles, int num_muscles, const std::string& what) {
  if (muscles.empty()) throw InvalidInputError(what + ": no muscle");
  for (int m : muscles)
    if (m < 0 || m >= num_muscles) {
      std::ostringstream msg;
      msg << what << ": muscle " << m << " is out of range [0, " << num_muscles << ")";
      throw InvalidInputError(msg.str());
    }
}

void CheckSceneMuscles(const Scene& scene, int num_muscles, const std::string& what) {
  if (static_cast<int>(scene.muscles.size()) != num_muscles) {
    std::ostringstream msg;
    msg << what << ": made for " << num_muscles << " muscles, the scene has " << scene.muscles.size();
    throw InvalidInputError(msg.str());
  }
}

void CheckSteps(int expected, int num_steps, const std::string& what) {
  if (expected != num_steps) {
    std::ostringstream msg;
    msg << what << ": made for " << expected << " steps, the rollout has " << num_steps;
    throw InvalidInputError(msg.str());
  }
}

// The activation vector of step k, filled with 1 (rest) if empty.
VectorXd& Activation(solvers::RolloutSetup* setup, size_t k, int num_muscles) {
  VectorXd& a = setup->inputs[k].activation;
  if (a.size() == 0) a = VectorXd::Ones(num_muscles);
  return a;
}

// dL/da_k[m], zero where the gradient has no entry.
double ActivationGradient(const RolloutGradient& grad, size_t k, int m) {
  if (k >= grad.activation.size() || grad.activation[k].size() == 0) return 0;
  return grad.activation[k](m);
}

}  // namespace

// ---- ConstantActivationVariables ---------------------------------------------

ConstantActivationVariables::ConstantActivationVariables(std::vector<int> muscles, int num_muscles)
    : ReverseModeBlock(static_cast<int>(muscles.size())), muscles_(std::move(muscles)), num_muscles_(num_muscles) {
  CheckMuscles(muscles_, num_muscles_, name());
  SetInitial(VectorXd::Ones(size()));
}

void ConstantActivationVariables::CheckFits(const Scene& scene, int num_steps) const {
  CheckSceneMuscles(scene, num_muscles_, name());
}

void ConstantActivationVariables::Apply(const Eigen::Ref<const VectorXd>& values, solvers::RolloutSetup* setup) const {
  for (size_t k = 0; k < setup->inputs.size(); ++k) {
    VectorXd& a = Activation(setup, k, num_muscles_);
    for (size_t j = 0; j < muscles_.size(); ++j) a(muscles_[j]) = values(j);
  }
}

void ConstantActivationVariables::PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                                           Eigen::Ref<VectorXd> out) const {
  out.setZero();
  for (size_t k = 0; k < grad.activation.size(); ++k)
    for (size_t j = 0; j < muscles_.size(); ++j) out(j) += ActivationGradient(grad, k, muscles_[j]);
}

// ---- WindowedActivationVariables ---------------------------------------------

WindowedActivationVariables::WindowedActivationVariables(std::vector<int> muscles, int num_muscles, int num_steps,
                                                         int window)
    : ReverseModeBlock(0),
      muscles_(std::move(muscles)),
      num_muscles_(num_muscles),
      num_steps_(num_steps),
      window_(window) {
  CheckMuscles(muscles_, num_muscles_, name());
  if (window_ < 1 || num_steps_ < window_ || num_steps_ % window_ != 0) {
    std::ostringstream msg;
    msg << name() << ": num_steps = " << num_steps_
        << " is invalid: must be a positive multiple of window = " << window_ << " (>= 1)";
    throw InvalidInputError(msg.str());
  }
  Append(num_frames() * static_cast<int>(muscles_.size()));
  SetInitial(VectorXd::Ones(size()));
}

void WindowedActivationVariables::CheckFits(const Scene& scene, int num_steps) const {
  CheckSceneMuscles(scene, num_muscles_, name());
  CheckSteps(num_steps_, num_steps, name());
}

void WindowedActivationVariables::Apply(const Eigen::Ref<const VectorXd>& values, solvers::RolloutSetup* setup) const {
  const int groups = static_cast<int>(muscles_.size()), frames = num_frames();
  for (int k = 0; k < num_steps_; ++k) {
    const int c = k / window_, next = std::min(c + 1, frames - 1);
    const double t = static_cast<double>(k % window_) / window_;
    VectorXd& a = Activation(setup, k, num_muscles_);
    for (int g = 0; g < groups; ++g) a(muscles_[g]) = (1 - t) * values(c * groups + g) + t * values(next * groups + g);
  }
}

void WindowedActivationVariables::PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                                           Eigen::Ref<VectorXd> out) const {
  const int groups = static_cast<int>(muscles_.size()), frames = num_frames();
  out.setZero();
  for (int k = 0; k < num_steps_; ++k) {
    const int c = k / window_, next = std::min(c + 1, frames - 1);
    const double t = static_cast<double>(k % window_) / window_;
    for (int g = 0; g < groups; ++g) {
      const double d = ActivationGradient(grad, k, muscles_[g]);
      out(c * groups + g) += (1 - t) * d;
      out(next * groups + g) += t * d;
    }
  }
}

int WindowedActivationVariables::FirstAffectedState(int j) const {
  const int c = j / static_cast<int>(muscles_.size());
  // Frame c enters window c at t = 0 (step c window) and window c - 1 from its
  // second step on.
  return c == 0 ? 1 : (c - 1) * window_ + 2;
}

// ---- GaitActivationVariables ---------------------------------------------------

GaitActivationVariables::GaitActivationVariables(std::vector<GaitMuscle> muscles, int num_muscles, int num_steps,
                                                 double peak)
    : ReverseModeBlock(3), muscles_(std::move(muscles)), num_muscles_(num_muscles), num_steps_(num_steps), peak_(peak) {
  std::vector<int> indices;
  for (const GaitMuscle& m : muscles_) indices.push_back(m.muscle);
  CheckMuscles(indices, num_muscles_, name());
  if (num_steps_ < 1) {
    std::ostringstream msg;
    msg << name() << ": num_steps = " << num_steps_ << " is invalid: must be >= 1";
    throw InvalidInputError(msg.str());
  }
  if (!(std::isfinite(peak_) && peak_ > 0)) {
    std::ostringstream msg;
    msg << name() << ": peak = " << peak_ << " is invalid: must be finite and > 0";
    throw InvalidInputError(msg.str());
  }
}

void GaitActivationVariables::CheckFits(const Scene& scene, int num_steps) const {
  CheckSceneMuscles(scene, num_muscles_, name());
  CheckSteps(num_steps_, num_steps, name());
}

void GaitActivationVariables::Apply(const Eigen::Ref<const VectorXd>& values, solvers::RolloutSetup* setup) const {
  const double w = values(2);
  for (int i = 0; i < num_steps_; ++i) {
    VectorXd& a = Activation(setup, i, num_muscles_);
    const double s = std::sin(w * i);
    for (const GaitMuscle& m : muscles_) {
      const double amplitude = m.front_leg ? values(0) : values(1);
      a(m.muscle) = peak_ * (1 + (m.forward ? 1 : -1) * amplitude * s) / 2;
    }
  }
}

void GaitActivationVariables::PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                                       Eigen::Ref<VectorXd> out) const {
  const double w = values(2);
  out.setZero();
  for (int i = 0; i < num_steps_; ++i) {
    const double s = std::sin(w * i), c = std::cos(w * i);
    for (const GaitMuscle& m : muscles_) {
      const double d = ActivationGradient(grad, i, m.muscle) * peak_ * (m.forward ? 1 : -1) / 2;
      const double amplitude = m.front_leg ? values(0) : values(1);
      out(m.front_leg ? 0 : 1) += d * s;
      out(2) += d * amplitude * i * c;
    }
  }
}

// ---- ConstantForceVariables ------------------------------------------------------

ConstantForceVariables::ConstantForceVariables(int num_dofs) : ReverseModeBlock(num_dofs) {
  if (num_dofs <= 0 || num_dofs % 3 != 0) {
    std::ostringstream msg;
    msg << name() << ": num_dofs = " << num_dofs << " is invalid: must be a positive multiple of 3";
    throw InvalidInputError(msg.str());
  }
}

void ConstantForceVariables::CheckFits(const Scene& scene, int num_steps) const {
  if (scene.mesh.num_dofs() != size()) {
    std::ostringstream msg;
    msg << name() << ": made for " << size() << " DoFs, the mesh has " << scene.mesh.num_dofs();
    throw InvalidInputError(msg.str());
  }
}

void ConstantForceVariables::Apply(const Eigen::Ref<const VectorXd>& values, solvers::RolloutSetup* setup) const {
  for (StepInput& input : setup->inputs) {
    if (input.external_force.size() == 0) input.external_force = VectorXd::Zero(size());
    input.external_force += values;
  }
}

void ConstantForceVariables::PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                                      Eigen::Ref<VectorXd> out) const {
  out.setZero();
  for (const VectorXd& g : grad.external_force)
    if (g.size()) out += g;
}

}  // namespace diffpd::problems
