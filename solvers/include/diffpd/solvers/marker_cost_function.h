// Ceres cost function of captured-marker residuals (calibration_model.h).
//
//   CalibrationModel model(setup);
//   double material[2];
//   model.InitialMaterialBlock(material);
//   RolloutEvaluationCallback callback(&model, {material});
//   ceres::Problem::Options po;
//   po.evaluation_callback = &callback;  // one rollout per evaluation point
//   ceres::Problem problem(po);
//   AddMarkerResidualBlocks(&problem, &model, {material});
//
// Residuals: the rows of CalibrationModel::residuals() of the chosen samples
// (3 per sample, x y z). Parameter blocks: the model's, in its order. All
// blocks of one model share its cached rollout: with the evaluation callback
// the simulation runs once per point before Ceres evaluates the blocks; without
// it the first block evaluated at a point runs it (so the cost function is
// also correct alone, e.g. under ceres::GradientChecker).
#pragma once

#include <vector>

#include <ceres/cost_function.h>
#include <ceres/evaluation_callback.h>
#include <ceres/problem.h>

#include "diffpd/solvers/calibration_model.h"

namespace diffpd::solvers {

class MarkerCostFunction : public ceres::CostFunction {
 public:
  // Residuals of `samples` (indices into model->observations(); empty: all).
  // Does not take ownership of `model`, which must outlive this object.
  // Throws InvalidInputError for an out-of-range or repeated sample index.
  explicit MarkerCostFunction(CalibrationModel* model, std::vector<int> samples = {});

  // Honours the Ceres contract: jacobians == nullptr or jacobians[i] ==
  // nullptr means "not wanted"; blocks are row-major (residual-major).
  // Returns false (never throws) when the rollout or its derivative fails.
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

  const std::vector<int>& samples() const { return samples_; }

 private:
  CalibrationModel* model_;
  std::vector<int> samples_;
};

// Runs the model's rollout (and, when Ceres asks for Jacobians, its
// derivative) once per evaluation point, reading the point from the user's
// parameter blocks, before Ceres evaluates the cost functions. Failures are
// recorded in the model; the cost functions then return false.
class RolloutEvaluationCallback : public ceres::EvaluationCallback {
 public:
  // `blocks`: the parameter blocks given to the residual blocks, in the
  // model's order. Does not take ownership of anything.
  RolloutEvaluationCallback(CalibrationModel* model, std::vector<double*> blocks);
  void PrepareForEvaluation(bool evaluate_jacobians, bool new_evaluation_point) override;

 private:
  CalibrationModel* model_;
  std::vector<double*> blocks_;
};

enum class ResidualBlocks {
  kOnePerFrame,  // one residual block per capture time (shares the rollout)
  kSingle,       // one block with every sample
};

// Adds MarkerCostFunction residual blocks (owned by the problem) over
// `blocks` (the model's parameter blocks, in its order) and returns their ids.
// Throws InvalidInputError if the number of blocks is not the model's.
std::vector<ceres::ResidualBlockId> AddMarkerResidualBlocks(ceres::Problem* problem, CalibrationModel* model,
                                                            const std::vector<double*>& blocks,
                                                            ResidualBlocks layout = ResidualBlocks::kOnePerFrame);

}  // namespace diffpd::solvers
