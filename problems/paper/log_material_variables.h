// Material parameters as natural logarithms: variable x = ln(parameter), so
// E = e^x (Pa), nu = e^x, rho = e^x (kg/m^3). The paper's plant and bouncing
// ball rows optimise (ln E, ln nu) this way; dL/dx = dL/dp * p.
#pragma once

#include <string>
#include <vector>

#include "diffpd/solvers/core/material_block.h"
#include "paper/reverse_mode_block.h"

namespace diffpd::problems {

class LogMaterialVariables : public ReverseModeBlock {
 public:
  using Field = solvers::MaterialField;
  // One variable per field, in this order; starting values ln of `start`'s
  // parameters. Throws InvalidInputError if fields is empty or repeats one.
  LogMaterialVariables(std::vector<Field> fields, const MaterialParameters& start);
  std::string name() const override { return "log_material"; }
  void CheckFits(const Scene& scene, int num_steps) const override {}
  // Overwrites those fields of setup->material with e^x.
  void Apply(const Eigen::Ref<const VectorXd>& values, solvers::RolloutSetup* setup) const override;
  void PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                Eigen::Ref<VectorXd> out) const override;
  int FirstAffectedState(int j) const override { return 1; }

 private:
  std::vector<Field> fields_;
};

}  // namespace diffpd::problems
