#include "diffpd/rollout.h"

namespace diffpd {

double Rollout::forward_seconds() const {
  double s = 0;
  for (const StepReport& r : reports) s += r.seconds;
  return s;
}

}  // namespace diffpd
