#include "paper/log_material_variables.h"

#include <cmath>

#include "diffpd/error.h"

namespace diffpd::problems {
namespace {

using Field = solvers::MaterialField;

double& Parameter(MaterialParameters* m, Field f) {
  return f == Field::kYoungsModulus ? m->youngs_modulus : f == Field::kPoissonsRatio ? m->poissons_ratio : m->density;
}

double Derivative(const RolloutGradient& g, Field f) {
  return f == Field::kYoungsModulus ? g.youngs_modulus : f == Field::kPoissonsRatio ? g.poissons_ratio : g.density;
}

}  // namespace

LogMaterialVariables::LogMaterialVariables(std::vector<Field> fields, const MaterialParameters& start)
    : ReverseModeBlock(static_cast<int>(fields.size())), fields_(std::move(fields)) {
  if (fields_.empty()) throw InvalidInputError("log_material: no field");
  VectorXd initial(fields_.size());
  MaterialParameters m = start;
  for (size_t i = 0; i < fields_.size(); ++i) {
    for (size_t j = 0; j < i; ++j)
      if (fields_[j] == fields_[i]) throw InvalidInputError("log_material: a field is listed twice");
    initial(i) = std::log(Parameter(&m, fields_[i]));
  }
  SetInitial(initial);
}

void LogMaterialVariables::Apply(const Eigen::Ref<const VectorXd>& values, solvers::RolloutSetup* setup) const {
  for (size_t i = 0; i < fields_.size(); ++i) Parameter(&setup->material, fields_[i]) = std::exp(values(i));
}

void LogMaterialVariables::PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                                    Eigen::Ref<VectorXd> out) const {
  for (size_t i = 0; i < fields_.size(); ++i) out(i) = Derivative(grad, fields_[i]) * std::exp(values(i));
}

}  // namespace diffpd::problems
