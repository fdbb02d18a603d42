// Lumped mass of a body whose density is constant per material part
// (internal; parts as in scene/material_regions.h):
//
//   M = sum_p rho_p m_p   (3n, kg),
//
// m_p the unit-density lumped mass of part p's elements (FemModel::
// UnitLumpedMass, each node's value repeated for x, y and z). When every part
// has the same density rho, M = rho m with m = FemModel::unit_lumped_mass():
// the arithmetic of a body without regions, bit for bit.
#pragma once

#include <vector>

#include "diffpd/types.h"
#include "fem/fem_model.h"

namespace diffpd::internal {

class MassModel {
 public:
  // part_of_element: num_elements entries in [0, num_parts), or empty (one part).
  MassModel(const FemModel& fem, const std::vector<int>& part_of_element, int num_parts);

  int num_parts() const { return static_cast<int>(part_unit_mass_.size()); }
  // Sets rho_p (num_parts values, kg/m^3, validated by the caller) and M.
  void SetDensities(const std::vector<double>& densities);
  const VectorXd& mass() const { return mass_; }                                    // M (3n, kg)
  const VectorXd& unit_mass() const { return unit_mass_; }                          // m = sum_p m_p (3n, m^3)
  const VectorXd& part_unit_mass(int part) const { return part_unit_mass_[part]; }  // m_p (3n)

  // dM along a density direction: sum_p drho_p m_p (3n); drho has num_parts entries.
  VectorXd Direction(const VectorXd& drho) const;
  // dL/drho_p = dmass . m_p for every part, from dmass = dL/dM (3n, the diagonal).
  VectorXd DensityGradient(const VectorXd& dmass) const;

 private:
  VectorXd unit_mass_;
  std::vector<VectorXd> part_unit_mass_;
  VectorXd mass_;
};

}  // namespace diffpd::internal
