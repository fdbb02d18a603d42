// Adam (Kingma and Ba 2015) as the original DiffPD swimmers trained their
// controllers (torch 1.4's torch.optim.Adam with L2 weight decay, a global
// gradient-norm clip before the step and a linearly decaying learning rate):
// per step e = 0, 1, ... with the loss gradient g at theta,
//
//   g <- g * min(1, clip_norm / (|g| + 1e-6))       (clip_grad_norm_; clip_norm <= 0: none)
//   g <- g + weight_decay * theta
//   m <- beta1 m + (1 - beta1) g,   s <- beta2 s + (1 - beta2) g^2
//   lr_e = learning_rate * (1 - e / schedule_steps) (schedule_steps <= 0: constant)
//   theta <- theta - lr_e / (1 - beta1^(e+1)) * m / (sqrt(s) / sqrt(1 - beta2^(e+1)) + epsilon).
#pragma once

#include "diffpd/types.h"

namespace diffpd::problems {

struct AdamOptions {
  double learning_rate = 1e-3;  // > 0
  double beta1 = 0.9;           // in [0, 1)
  double beta2 = 0.999;         // in [0, 1)
  double epsilon = 1e-8;        // > 0
  double weight_decay = 1e-4;   // >= 0, added to the gradient as weight_decay * theta
  double clip_norm = 1.0;       // > 0: the gradient's 2-norm is clipped to it; <= 0: no clip
  // The learning rate falls linearly to 0 at this step (the original: 1000);
  // <= 0: constant.
  int schedule_steps = 1000;
  // Throws InvalidInputError naming the field, e.g. "adam: beta1 = 1 is invalid: must be in [0, 1)".
  void Validate() const;
};

class Adam {
 public:
  // Validates the options; the moments start at zero for n parameters.
  Adam(const AdamOptions& options, int num_parameters);
  // One update of *theta (n entries) from the loss gradient (n entries,
  // finite: InvalidInputError otherwise, "adam: the gradient has a
  // non-finite entry"). Returns the learning rate used.
  double Step(const VectorXd& gradient, VectorXd* theta);
  int steps_taken() const { return steps_; }

 private:
  AdamOptions options_;
  VectorXd m_, s_;
  int steps_ = 0;
};

}  // namespace diffpd::problems
