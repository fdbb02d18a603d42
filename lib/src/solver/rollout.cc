#include "diffpd/rollout.h"

#include <algorithm>
#include <sstream>

#include "diffpd/error.h"

namespace diffpd {

double Rollout::forward_seconds() const {
  double s = 0;
  for (const StepReport& r : reports) s += r.seconds;
  return s;
}

Rollout Rollout::Truncated(int num_steps) const {
  const int steps = this->num_steps();
  if (num_steps < 0 || num_steps > steps || static_cast<int>(states.size()) < num_steps + 1) {
    std::ostringstream msg;
    msg << "Truncated: num_steps = " << num_steps << " is out of range [0, " << steps << "]";
    throw InvalidInputError(msg.str());
  }
  Rollout out;
  out.states.assign(states.begin(), states.begin() + num_steps + 1);
  out.inputs.assign(inputs.begin(), inputs.begin() + num_steps);
  out.reports.assign(reports.begin(), reports.begin() + std::min<size_t>(num_steps, reports.size()));
  out.material = material;
  out.region_materials = region_materials;
  out.options = options;
  if (closed_loop()) {
    out.controller_memory.assign(controller_memory.begin(),
                                 controller_memory.begin() + std::min<size_t>(num_steps + 1, controller_memory.size()));
    out.controller_parameters = controller_parameters;
  }
  return out;
}

}  // namespace diffpd
