// Forward-mode derivatives (tangents) of a rollout: how every state x_k, v_k
// changes along given directions in the space of the rollout's
// differentiable inputs. Produced by Simulator::Tangents (simulator.h).
//
// With P directions the tangent pass costs one linear solve with the step's
// exact Hessian per step for all P directions together (P right-hand sides
// sharing one factorisation), so it pays when P is small and the outputs
// are many (e.g. the Jacobian of many marker residuals w.r.t. a few material
// parameters); with one scalar loss and many inputs use Backward instead.
#pragma once

#include <functional>
#include <vector>

#include "diffpd/rollout.h"
#include "diffpd/types.h"

namespace diffpd {

// One direction d in the space of a rollout's differentiable inputs. The
// tangent along d is the derivative of the rollout at epsilon = 0 when every
// input theta is replaced by theta + epsilon d_theta. Empty vectors mean zero.
struct InputDirection {
  VectorXd x0;                           // 3n, m: initial positions
  VectorXd v0;                           // 3n, m/s: initial velocities
  std::vector<VectorXd> external_force;  // empty, or one per step (each 3n or empty), N
  std::vector<VectorXd> activation;      // empty, or one per step (each one per muscle or empty)
  // The base material (Scene::material; elements in no region).
  double youngs_modulus = 0;  // Pa
  double poissons_ratio = 0;  // dimensionless
  double density = 0;         // kg/m^3
  // Empty (zero), or one per Scene::material_regions entry, in order: the
  // direction's components for region r's E (Pa), nu and rho (kg/m^3).
  std::vector<MaterialComponents> region_materials;
  // The declared state forces' parameters (state_forces.h), laid out as
  // their gradient: linear damping (1/s), fluid density (kg/m^3), drag and
  // thrust coefficients, flow velocity (m/s), penalty friction per
  // Scene::penalty_contacts entry (empty: zero), the quad hydrodynamics'
  // fluid density, flow velocity and curve control values. Components of
  // terms the scene does not declare must be zero.
  StateForceGradient state_forces;

  // The unit direction of one base-material parameter.
  static InputDirection YoungsModulus();
  static InputDirection PoissonsRatio();
  static InputDirection Density();
  // The unit direction of one parameter of material region `region` of a
  // scene with `num_regions` regions. Throws InvalidInputError unless
  // 0 <= region < num_regions.
  static InputDirection RegionYoungsModulus(int region, int num_regions);
  static InputDirection RegionPoissonsRatio(int region, int num_regions);
  static InputDirection RegionDensity(int region, int num_regions);
};

// Tangents of a rollout with K steps along P directions.
struct TangentRollout {
  // dx[k] and dv[k], k = 0..K, are 3n x P: column p holds d x_k / d epsilon
  // (m per unit of direction p) and d v_k / d epsilon along direction p.
  // Fixed (Dirichlet) DoFs have dx = 0 for k >= 1.
  std::vector<MatrixXd> dx;
  std::vector<MatrixXd> dv;
  // Linear iterations of the iterative solves (all columns), fallbacks to a
  // direct solve, and the wall-clock time of the whole pass.
  BackwardReport report;

  int num_steps() const { return static_cast<int>(dx.size()) - 1; }
  int num_directions() const { return dx.empty() ? 0 : static_cast<int>(dx[0].cols()); }
};

// Receives state k of a rollout and its tangents dx_k, dv_k (3n x P, as in
// TangentRollout) as a tangent pass computes them, k = 0, 1, ..., K in order
// (Simulator::Tangents over a checkpointed rollout).
using TangentConsumer = std::function<void(int k, const State& state, const MatrixXd& dx, const MatrixXd& dv)>;

}  // namespace diffpd
