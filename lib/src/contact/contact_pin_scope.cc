#include "contact/contact_pin_scope.h"

namespace diffpd::internal {

ContactPinScope::ContactPinScope(SimulatorImpl& sim, const std::vector<int>& nodes, const VectorXd& positions)
    : sim_(sim), nodes_(nodes) {
  if (nodes_.empty()) return;
  const Method m = sim.options.method;
  if (m == Method::kPd || m == Method::kPdLbfgs) {
    // Built (with the scene's own Dirichlet set) before the pins are added.
    pd_ = &sim.pd_system();
    try {
      pd_->SetActiveNodes(nodes_, sim.scene.frictional_contact_options.pd_linear_solve);
    } catch (...) {
      pd_->SetActiveNodes({}, sim.scene.frictional_contact_options.pd_linear_solve);
      throw;
    }
  }
  for (const int i : nodes_)
    for (int d = 0; d < 3; ++d) {
      sim.fixed[3 * i + d] = 1;
      sim.fixed_values(3 * i + d) = positions(3 * i + d);
    }
}

ContactPinScope::~ContactPinScope() {
  for (const int i : nodes_)
    for (int d = 0; d < 3; ++d) {
      sim_.fixed[3 * i + d] = 0;
      sim_.fixed_values(3 * i + d) = 0.0;
    }
  if (pd_) pd_->SetActiveNodes({}, sim_.scene.frictional_contact_options.pd_linear_solve);
}

}  // namespace diffpd::internal
