// Material parameters (validation, Lame parameters) and energy names.
#include "diffpd/material.h"

#include <cmath>
#include <sstream>

#include "diffpd/error.h"

namespace diffpd {
namespace {

std::string InvalidMessage(const char* name, double value, const char* requirement) {
  std::ostringstream message;
  message << name << " = " << value << " is invalid: must be " << requirement;
  return message.str();
}

}  // namespace

void MaterialParameters::Validate() const {
  if (!(std::isfinite(youngs_modulus) && youngs_modulus > 0.0)) {
    throw InvalidInputError(InvalidMessage("youngs_modulus", youngs_modulus, "finite and > 0 (Pa)"));
  }
  if (!(poissons_ratio > -1.0 && poissons_ratio < 0.5)) {
    throw InvalidInputError(InvalidMessage("poissons_ratio", poissons_ratio, "finite and in (-1, 0.5)"));
  }
  if (!(std::isfinite(density) && density > 0.0)) {
    throw InvalidInputError(InvalidMessage("density", density, "finite and > 0 (kg/m^3)"));
  }
}

double MaterialParameters::mu() const { return youngs_modulus / (2.0 * (1.0 + poissons_ratio)); }

double MaterialParameters::lambda() const {
  const double nu = poissons_ratio;
  return youngs_modulus * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
}

void MaterialParameters::LameDerivatives(double* dmu_dE, double* dmu_dnu, double* dlambda_dE,
                                         double* dlambda_dnu) const {
  const double E = youngs_modulus, nu = poissons_ratio;
  const double denominator = (1.0 + nu) * (1.0 - 2.0 * nu);
  if (dmu_dE != nullptr) *dmu_dE = 1.0 / (2.0 * (1.0 + nu));
  if (dmu_dnu != nullptr) *dmu_dnu = -E / (2.0 * (1.0 + nu) * (1.0 + nu));
  if (dlambda_dE != nullptr) *dlambda_dE = nu / denominator;
  // d/dnu [nu / ((1 + nu)(1 - 2 nu))] = (1 + 2 nu^2) / ((1 + nu)(1 - 2 nu))^2.
  if (dlambda_dnu != nullptr) *dlambda_dnu = E * (1.0 + 2.0 * nu * nu) / (denominator * denominator);
}

const char* ToString(ElasticEnergy energy) {
  switch (energy) {
    case ElasticEnergy::kLinear:
      return "linear";
    case ElasticEnergy::kCorotated:
      return "corotated";
    case ElasticEnergy::kNeoHookean:
      return "neohookean";
    case ElasticEnergy::kPdCorotated:
      return "pd-corotated";
    case ElasticEnergy::kPdVolume:
      return "pd-volume";
  }
  DIFFPD_CHECK(false, "unknown ElasticEnergy " << static_cast<int>(energy));
}

bool IsElasticEnergy(ElasticEnergy energy) {
  switch (energy) {
    case ElasticEnergy::kLinear:
    case ElasticEnergy::kCorotated:
    case ElasticEnergy::kNeoHookean:
    case ElasticEnergy::kPdCorotated:
    case ElasticEnergy::kPdVolume:
      return true;
  }
  return false;
}

bool IsProjective(ElasticEnergy energy) {
  return energy == ElasticEnergy::kPdCorotated || energy == ElasticEnergy::kPdVolume;
}

}  // namespace diffpd
