// Per-energy density kernels used by the solvers (internal).
//
// Each function evaluates one ElasticEnergy (formulas in diffpd/material.h)
// and is linear in (mu, lambda) (Pa): energy in J/m^3, stress P = dPsi/dF in
// Pa, stress differential dP/dF as a 9x9 matrix in the column-major
// flattening of types.h. The SVD-based energies (corotated, pd-corotated,
// pd-volume) are evaluated in the singular-value frame, F = U diag(sigma) V^T:
//   corotated:    Psi = mu sum (sigma_i - 1)^2 + (lambda/2)(J - 1)^2,
//                 P = U diag(2 mu (sigma_i - 1) + lambda (J - 1) J / sigma_i) V^T;
//   pd-corotated: the mu part of corotated (w = 2 mu, Proj = U V^T);
//   pd-volume:    Psi = (lambda/2) |sigma - d|^2, P = lambda U diag(sigma - d) V^T,
//                 d = ProjectSingularValuesToUnitDeterminant(sigma);
// and their differentials are assembled from closed-form coefficients (see
// isotropic_differential.h). Linear and neo-Hookean need no SVD and use the
// reference formulas. Neo-Hookean throws SolverError(kInvertedElement) for
// det F <= 0, as the reference does.
#pragma once

#include "diffpd/material.h"
#include "diffpd/types.h"
#include "material/isotropic_differential.h"
#include "material/projections.h"
#include "material/svd3.h"

namespace diffpd::internal {

// True for the energies whose kernels use the SVD of F.
bool NeedsSvd(ElasticEnergy energy);

// Plain kernels (compute the SVD themselves when needed). Call the 4-argument
// StressDifferential qualified, internal::StressDifferential(...): argument-
// dependent lookup also finds diffpd::StressDifferential (same parameters),
// so an unqualified call is ambiguous.
double Energy(ElasticEnergy energy, const Mat3& F, double mu, double lambda);
Mat3 Stress(ElasticEnergy energy, const Mat3& F, double mu, double lambda);
Mat9 StressDifferential(ElasticEnergy energy, const Mat3& F, double mu, double lambda);

// Combined kernels with svd = ComputeSvd3(F) precomputed (ignored by the
// energies that do not need it): the energy density, and the stress into
// *stress when stress != nullptr. `volume`, when given, is
// ProjectSingularValuesToUnitDeterminant(svd.sigma) precomputed (pd-volume).
double EnergyAndStress(ElasticEnergy energy, const Mat3& F, const Svd3& svd, double mu, double lambda, Mat3* stress,
                       const VolumeProjection* volume = nullptr);
Mat9 StressDifferential(ElasticEnergy energy, const Mat3& F, const Svd3& svd, double mu, double lambda);
// The singular-value form of StressDifferential for the energies with
// NeedsSvd (aborts for the others): dP/dF =
// AssembleIsotropicDifferential(svd, coefficients), so the coefficients of
// several energies at one F add up and assemble once. `volume` as above.
IsotropicDifferentialCoefficients StressDifferentialCoefficients(ElasticEnergy energy, const Svd3& svd, double mu,
                                                                 double lambda,
                                                                 const VolumeProjection* volume = nullptr);

// The PD form (w/2) |F - Proj(F)|^2 of a projective energy (IsProjective must
// hold; aborts otherwise): the weight w (Pa; 2 mu for pd-corotated, lambda for
// pd-volume), the projection Proj(F) (3x3) and dProj/dF (9x9).
double ProjectiveWeight(ElasticEnergy energy, double mu, double lambda);
Mat3 Projection(ElasticEnergy energy, const Svd3& svd);
Mat9 ProjectionDifferential(ElasticEnergy energy, const Svd3& svd);

}  // namespace diffpd::internal
