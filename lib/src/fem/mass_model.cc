#include "fem/mass_model.h"

#include "diffpd/error.h"

namespace diffpd::internal {
namespace {

VectorXd PerDof(const VectorXd& node_values) {
  VectorXd out(3 * node_values.size());
  for (Eigen::Index i = 0; i < node_values.size(); ++i) out.segment<3>(3 * i).setConstant(node_values(i));
  return out;
}

}  // namespace

MassModel::MassModel(const FemModel& fem, const std::vector<int>& part_of_element, int num_parts)
    : unit_mass_(PerDof(fem.unit_lumped_mass())) {
  DIFFPD_CHECK(num_parts >= 1 && (num_parts == 1 || !part_of_element.empty()),
               num_parts << " parts need a part per element");
  if (num_parts == 1) {
    part_unit_mass_ = {unit_mass_};
  } else {
    for (int p = 0; p < num_parts; ++p) part_unit_mass_.push_back(PerDof(fem.UnitLumpedMass(part_of_element, p)));
  }
  mass_ = unit_mass_;
}

void MassModel::SetDensities(const std::vector<double>& densities) {
  DIFFPD_CHECK(static_cast<int>(densities.size()) == num_parts(), densities.size()
                                                                      << " densities for " << num_parts() << " parts");
  bool uniform = true;
  for (const double rho : densities) uniform = uniform && rho == densities[0];
  if (uniform) {
    mass_ = densities[0] * unit_mass_;
    return;
  }
  mass_ = densities[0] * part_unit_mass_[0];
  for (int p = 1; p < num_parts(); ++p) mass_ += densities[p] * part_unit_mass_[p];
}

VectorXd MassModel::Direction(const VectorXd& drho) const {
  DIFFPD_CHECK(drho.size() == num_parts(), drho.size() << " density components for " << num_parts() << " parts");
  VectorXd out = drho(0) * part_unit_mass_[0];
  for (int p = 1; p < num_parts(); ++p) out += drho(p) * part_unit_mass_[p];
  return out;
}

VectorXd MassModel::DensityGradient(const VectorXd& dmass) const {
  VectorXd out(num_parts());
  for (int p = 0; p < num_parts(); ++p) out(p) = dmass.dot(part_unit_mass_[p]);
  return out;
}

}  // namespace diffpd::internal
