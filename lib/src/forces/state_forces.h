// Explicit forces that depend on the state at the start of a step (internal):
// linear damping, hydrodynamic drag and thrust (on triangles and on one-sided
// quads), penalty-contact friction (see diffpd/state_forces.h,
// diffpd/quad_hydrodynamics.h and diffpd/contact.h for the models). Evaluated once
// per step at (x_i, v_i); the backward pass needs their vector-Jacobian
// products, the tangent pass their Jacobian-vector products. Every method
// returns at once when nothing is declared.
#pragma once

#include <optional>
#include <vector>

#include "diffpd/scene.h"
#include "diffpd/state_forces.h"
#include "diffpd/types.h"

namespace diffpd::internal {

class StateForces {
 public:
  // The scene must be valid. Copies what it needs.
  explicit StateForces(const Scene& scene);

  bool empty() const { return !damping_ && !hydro_ && !quad_hydro_ && friction_.empty(); }

  // Every method takes the step's StepInput::wetted_quads (checked by the
  // caller): empty, or the quad faces held wet (1) or dry (0).
  //
  // *f += F(x, v; M) (3n) for the lumped mass M (3n, kg; enters damping's
  // -c M v).
  void Add(const VectorXd& x, const VectorXd& v, const VectorXd& mass, const std::vector<char>& wetted_quads,
           VectorXd* f) const;
  // Given w = dL/dF (3n): *gx += (dF/dx)^T w, *gv += (dF/dv)^T w, the
  // parameter gradients into *grad (penalty_friction sized on first use) and,
  // if dmass is not nullptr, *dmass += (dF/dM)^T w (3n, per DoF's mass).
  void AddVjp(const VectorXd& x, const VectorXd& v, const VectorXd& mass, const std::vector<char>& wetted_quads,
              const VectorXd& w, VectorXd* gx, VectorXd* gv, StateForceGradient* grad, VectorXd* dmass) const;
  // Jacobian-vector products along P directions: column p of *df (3n x P,
  // sized by the caller) += dF/dx dx.col(p) + dF/dv dv.col(p) + dF/dM
  // dmass[p] + dF/dtheta dtheta[p]. dmass: empty, or P entries each 3n or
  // empty (zero); dtheta: P parameter directions laid out as the gradient
  // (penalty_friction empty or one per Scene::penalty_contacts entry).
  void AddJvp(const VectorXd& x, const VectorXd& v, const VectorXd& mass, const std::vector<char>& wetted_quads,
              const MatrixXd& dx, const MatrixXd& dv, const std::vector<VectorXd>& dmass,
              const std::vector<StateForceGradient>& dtheta, MatrixXd* df) const;

 private:
  struct FrictionNode {
    int contact;  // index into scene.penalty_contacts
    int node;
    Vec3 normal;  // unit
    double offset, stiffness, mu, eps;
  };
  std::optional<double> damping_;
  std::optional<Hydrodynamics> hydro_;
  std::optional<QuadHydrodynamics> quad_hydro_;
  std::vector<FrictionNode> friction_;
  int num_penalty_contacts_ = 0;
};

}  // namespace diffpd::internal
