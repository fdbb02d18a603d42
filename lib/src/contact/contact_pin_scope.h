// Pins contact nodes as extra Dirichlet nodes for one step (internal).
#pragma once

#include <vector>

#include "diffpd/types.h"
#include "solver/simulator_impl.h"

namespace diffpd::internal {

// For its lifetime, all three axes of `nodes` (sorted, free in the scene) are
// fixed at positions.segment<3>(3 i) (positions is 3n): sim.fixed and
// sim.fixed_values include them, and for PD methods the PD system erases them
// from its solves (Woodbury or refactorisation, per the scene's
// frictional_contact_options). The destructor restores everything.
class ContactPinScope {
 public:
  ContactPinScope(SimulatorImpl& sim, const std::vector<int>& nodes, const VectorXd& positions);
  ~ContactPinScope();
  ContactPinScope(const ContactPinScope&) = delete;
  ContactPinScope& operator=(const ContactPinScope&) = delete;

 private:
  SimulatorImpl& sim_;
  std::vector<int> nodes_;
  PdSystem* pd_ = nullptr;
};

}  // namespace diffpd::internal
