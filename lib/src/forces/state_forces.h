// Explicit forces that depend on the state at the start of a step (internal):
// linear damping, hydrodynamic drag and thrust, penalty-contact friction (see
// diffpd/state_forces.h and diffpd/contact.h for the models). Evaluated once
// per step at (x_i, v_i); the backward pass needs their vector-Jacobian
// products. Every method returns at once when nothing is declared.
#pragma once

#include <optional>
#include <vector>

#include "diffpd/scene.h"
#include "diffpd/state_forces.h"
#include "diffpd/types.h"

namespace diffpd::internal {

class StateForces {
 public:
  // `unit_node_mass` is the lumped mass per node at unit density (n, m^3);
  // the scene must be valid. Copies what it needs.
  StateForces(const Scene& scene, const VectorXd& unit_node_mass);

  bool empty() const { return !damping_ && !hydro_ && friction_.empty(); }

  // *f += F(x, v) (3n) for body density rho (kg/m^3).
  void Add(const VectorXd& x, const VectorXd& v, double rho, VectorXd* f) const;
  // Given w = dL/dF (3n): *gx += (dF/dx)^T w, *gv += (dF/dv)^T w, the
  // parameter gradients into *grad (penalty_friction sized on first use);
  // returns w . dF/drho.
  double AddVjp(const VectorXd& x, const VectorXd& v, double rho, const VectorXd& w, VectorXd* gx, VectorXd* gv,
                StateForceGradient* grad) const;

 private:
  struct FrictionNode {
    int contact;  // index into scene.penalty_contacts
    int node;
    Vec3 normal;  // unit
    double offset, stiffness, mu, eps;
  };
  std::optional<double> damping_;
  std::optional<Hydrodynamics> hydro_;
  std::vector<FrictionNode> friction_;
  int num_penalty_contacts_ = 0;
  VectorXd unit_mass_;
};

}  // namespace diffpd::internal
