#include "control/adam.h"

#include <cmath>
#include <sstream>

#include "diffpd/error.h"

namespace diffpd::problems {
namespace {

[[noreturn]] void Invalid(const char* name, double value, const char* range) {
  std::ostringstream msg;
  msg << "adam: " << name << " = " << value << " is invalid: must be " << range;
  throw InvalidInputError(msg.str());
}

}  // namespace

void AdamOptions::Validate() const {
  if (!(std::isfinite(learning_rate) && learning_rate > 0)) Invalid("learning_rate", learning_rate, "finite and > 0");
  if (!(beta1 >= 0 && beta1 < 1)) Invalid("beta1", beta1, "in [0, 1)");
  if (!(beta2 >= 0 && beta2 < 1)) Invalid("beta2", beta2, "in [0, 1)");
  if (!(std::isfinite(epsilon) && epsilon > 0)) Invalid("epsilon", epsilon, "finite and > 0");
  if (!(std::isfinite(weight_decay) && weight_decay >= 0)) Invalid("weight_decay", weight_decay, "finite and >= 0");
  if (!std::isfinite(clip_norm)) Invalid("clip_norm", clip_norm, "finite (<= 0: no clip)");
}

Adam::Adam(const AdamOptions& options, int num_parameters)
    : options_((options.Validate(), options)), m_(VectorXd::Zero(num_parameters)), s_(VectorXd::Zero(num_parameters)) {}

double Adam::Step(const VectorXd& gradient, VectorXd* theta) {
  DIFFPD_CHECK(gradient.size() == m_.size() && theta->size() == m_.size(),
               "Adam: sizes " << gradient.size() << ", " << theta->size() << " for " << m_.size() << " parameters");
  if (!gradient.allFinite()) throw InvalidInputError("adam: the gradient has a non-finite entry");
  VectorXd g = gradient;
  if (options_.clip_norm > 0) {
    const double norm = g.norm();
    const double coefficient = options_.clip_norm / (norm + 1e-6);
    if (coefficient < 1) g *= coefficient;
  }
  g += options_.weight_decay * *theta;
  const double b1 = options_.beta1, b2 = options_.beta2;
  m_ = b1 * m_ + (1 - b1) * g;
  s_ = b2 * s_ + (1 - b2) * g.cwiseAbs2();
  double lr = options_.learning_rate;
  if (options_.schedule_steps > 0) lr *= 1.0 - static_cast<double>(steps_) / options_.schedule_steps;
  ++steps_;
  const double correction1 = 1 - std::pow(b1, steps_), correction2 = 1 - std::pow(b2, steps_);
  const VectorXd denominator = (s_.array().sqrt() / std::sqrt(correction2) + options_.epsilon).matrix();
  *theta -= (lr / correction1) * m_.cwiseQuotient(denominator);
  return lr;
}

}  // namespace diffpd::problems
