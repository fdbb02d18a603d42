#include "paper/row_rollout_function.h"

#include <string>
#include <utility>

#include "diffpd/error.h"

namespace diffpd::problems {
namespace {

// A row's block, shared with the row: every call goes to it; the bounds and
// starting values are copied when wrapped.
class SharedBlock : public solvers::ParameterBlock {
 public:
  explicit SharedBlock(std::shared_ptr<const solvers::ParameterBlock> block)
      : ParameterBlock(block->size()), block_(std::move(block)) {
    for (int j = 0; j < size(); ++j) SetBounds(j, 1, block_->lower()(j), block_->upper()(j));
    SetInitial(block_->initial());
  }
  std::string name() const override { return block_->name(); }
  void CheckFits(const Scene& scene, int num_steps) const override { block_->CheckFits(scene, num_steps); }
  void Apply(const Eigen::Ref<const VectorXd>& values, solvers::RolloutSetup* setup) const override {
    block_->Apply(values, setup);
  }
  void PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                Eigen::Ref<VectorXd> out) const override {
    block_->PullBack(values, grad, out);
  }
  int FirstAffectedState(int j) const override { return block_->FirstAffectedState(j); }
  bool SupportsForwardMode() const override { return block_->SupportsForwardMode(); }
  void PushForward(const Eigen::Ref<const VectorXd>& values, int j, const solvers::RolloutSetup& setup,
                   InputDirection* direction) const override {
    block_->PushForward(values, j, setup, direction);
  }

 private:
  std::shared_ptr<const solvers::ParameterBlock> block_;
};

// A row's loss term, shared with the row.
class SharedFunctional : public solvers::TrajectoryFunctional {
 public:
  explicit SharedFunctional(std::shared_ptr<const solvers::TrajectoryFunction> f) : f_(std::move(f)) {}
  std::string name() const override { return f_->name(); }
  int num_values() const override { return 1; }
  int LastStateOf(int i, int num_steps) const override { return f_->LastState(num_steps); }
  void Evaluate(const Rollout& rollout, Eigen::Ref<VectorXd> values) const override { values(0) = f_->Value(rollout); }
  void AddWeightedGradient(const Rollout& rollout, const Eigen::Ref<const VectorXd>& weights,
                           LossGradient* loss) const override {
    f_->AddGradient(rollout, weights(0), loss);
  }

 private:
  std::shared_ptr<const solvers::TrajectoryFunction> f_;
};

}  // namespace

RowRolloutFunction MakeRowRolloutFunction(const PaperRow& row, const SolverOptions& options) {
  if (row.prepare)
    throw InvalidInputError(row.name + ": the row needs its preparatory simulations first (PaperRow::Prepare)");
  Scene scene = row.scene;
  scene.material = row.base.material;
  RowRolloutFunction out;
  out.function = std::make_unique<solvers::RolloutFunction>(scene, options, row.steps);
  out.function->SetInitialState(row.base.initial);
  out.function->SetInputs(row.base.inputs);
  for (const auto& block : row.variables) out.function->AddBlock(std::make_unique<SharedBlock>(block));
  for (const LossTerm& term : row.loss) {
    const int index = out.function->AddFunctional(std::make_unique<SharedFunctional>(term.function));
    out.loss_rows.push_back(out.function->functional_row(index));
    out.loss_weights.push_back(term.weight);
  }
  return out;
}

}  // namespace diffpd::problems
