#include "forces/activation_scope.h"

#include <cmath>
#include <sstream>

#include "diffpd/error.h"

namespace diffpd::internal {

void CheckActivation(const VectorXd& activation, int num_muscles) {
  if (activation.size() == 0) return;
  if (activation.size() != num_muscles) {
    std::ostringstream msg;
    msg << "activation has " << activation.size() << " entries, expected " << num_muscles << " (one per muscle)";
    throw InvalidInputError(msg.str());
  }
  for (Eigen::Index j = 0; j < activation.size(); ++j)
    if (!std::isfinite(activation(j))) {
      std::ostringstream msg;
      msg << "activation[" << j << "] = " << activation(j) << " is invalid: must be finite";
      throw InvalidInputError(msg.str());
    }
}

}  // namespace diffpd::internal
