// Material parameters and elastic energy densities.
//
// Every density here is linear in the Lame parameters:
//   Psi(F) = mu * Psi_mu(F) + lambda * Psi_lambda(F),
//   mu = E / (2 (1 + nu)),  lambda = E nu / ((1 + nu)(1 - 2 nu)),
// which is what makes gradients w.r.t. Young's modulus and Poisson's ratio
// cheap: d(...)/d mu is the same expression evaluated with (mu, lambda) = (1, 0).
#pragma once

#include <string>
#include <vector>

#include "diffpd/types.h"

namespace diffpd {

struct MaterialParameters {
  double youngs_modulus = 1e6;   // E, Pa; must be finite and > 0
  double poissons_ratio = 0.45;  // nu, dimensionless; must lie in (-1, 0.5)
  double density = 1e3;          // rho, kg/m^3; must be finite and > 0

  // Throws InvalidInputError naming the parameter, its value and its range,
  // checking E, then nu, then rho; e.g.
  //   "youngs_modulus = 0 is invalid: must be finite and > 0 (Pa)"
  //   "poissons_ratio = 0.5 is invalid: must be finite and in (-1, 0.5)"
  //   "density = 0 is invalid: must be finite and > 0 (kg/m^3)"
  // (values printed with std::ostream's default formatting).
  void Validate() const;
  double mu() const;      // shear modulus, Pa
  double lambda() const;  // first Lame parameter, Pa
  // d mu / d E, d mu / d nu, d lambda / d E, d lambda / d nu:
  //   1 / (2 (1 + nu)),  -E / (2 (1 + nu)^2),
  //   nu / ((1 + nu)(1 - 2 nu)),  E (1 + 2 nu^2) / ((1 + nu)(1 - 2 nu))^2.
  // Any output pointer may be nullptr (not wanted).
  void LameDerivatives(double* dmu_dE, double* dmu_dnu, double* dlambda_dE, double* dlambda_dnu) const;
};

// One number per material parameter, in the parameters' units: a direction
// (dE in Pa, dnu, drho in kg/m^3) or a gradient (dL/dE per Pa, dL/dnu,
// dL/drho per kg/m^3). Used per material region (scene.h) by
// RolloutGradient (rollout.h) and InputDirection (tangent_rollout.h).
struct MaterialComponents {
  double youngs_modulus = 0;
  double poissons_ratio = 0;
  double density = 0;
};

// The elastic energy densities a scene may declare (a scene declares one or
// more; their densities add up).
enum class ElasticEnergy {
  // mu |eps|^2 + (lambda/2) tr(eps)^2, eps = (F + F^T)/2 - I. Newton only.
  kLinear,
  // mu |F - R|^2 + (lambda/2) (det F - 1)^2, R the rotation of F's polar
  // decomposition. Newton and PD-LBFGS.
  kCorotated,
  // (mu/2)(|F|^2 - 3) - mu log J + (lambda/2) (log J)^2, J = det F.
  // Undefined for J <= 0: evaluation throws SolverError(kInvertedElement) with
  // message "neohookean energy: det F = <J> <= 0 (inverted element)".
  kNeoHookean,
  // PD corotated: (w/2) |F - Proj_SO(3)(F)|^2 with w = 2 mu. PD-compatible.
  kPdCorotated,
  // PD volume preservation: (w/2) |F - Proj_{det=1}(F)|^2 with w = lambda,
  // the projection being the closest matrix of unit determinant. PD-compatible.
  kPdVolume,
};

// Its name ("linear", ..., "pd-volume"); aborts for a value that is no
// ElasticEnergy (Scene::Validate refuses those first).
const char* ToString(ElasticEnergy energy);
// True for the five declared values (false for an integer cast to the enum).
bool IsElasticEnergy(ElasticEnergy energy);
// True for energies of the PD form (w/2) min_{P in M} |F - P|^2.
bool IsProjective(ElasticEnergy energy);

// Energy density (J/m^3), first Piola-Kirchhoff stress P = dPsi/dF (Pa) and
// stress differential dP/dF (9x9, column-major flattening, see types.h) of one
// energy at deformation gradient F. These are the reference implementations
// the solvers' kernels are tested against. Where a rotation derivative
// dR/dF is involved (corotated, pd-corotated), its denominators
// sigma_i + sigma_j are clamped below at 1e-10 max(sigma_0, 1) (R jumps
// there: rank <= 1 or sigma_1 = -sigma_2); pd-volume's projection is the global
// minimiser, which jumps where two minimisers tie (large expansions, e.g.
// F = s I with s >~ 1.905).
double EnergyDensity(ElasticEnergy energy, const Mat3& F, double mu, double lambda);
Mat3 FirstPiolaStress(ElasticEnergy energy, const Mat3& F, double mu, double lambda);
Mat9 StressDifferential(ElasticEnergy energy, const Mat3& F, double mu, double lambda);

}  // namespace diffpd
