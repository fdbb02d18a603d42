// The differentiable rollout function: parameter blocks in, a rollout, the
// values of trajectory functionals and their exact derivatives out,
//
//   p (N parameters)  ->  setup(p)  ->  rollout  ->  v(p) = [r_1; r_2; ...] (M rows),
//
// with the rollout cached per parameter point. Optimiser adapters (Ceres
// cost functions, the Ipopt TNLP) are thin layers over it.
//
//   RolloutFunction f(scene, options, num_steps);      // the base setup: rest, no input
//   f.AddBlock(std::make_unique<MaterialBlock>(std::vector<MaterialBlock::Entry>{
//       MaterialField::kYoungsModulus, MaterialField::kPoissonsRatio}, scene));
//   const int markers = f.AddFunctional(std::make_unique<MarkerResiduals>(motion, scene.mesh, h, num_steps));
//   VectorXd v;  MatrixXd J;
//   f.Evaluate(f.initial_parameters(), f.RowsOf(markers), &v, &J);   // residuals, their N-column Jacobian
//
// Parameters: the blocks' values, block after block (AddBlock returns each
// block's offset). Rows: the functionals' values, functional after
// functional (AddFunctional returns each functional's index; RowsOf its rows).
//
// The setup at p is the base setup (SetInitialState, SetInputs; materials and
// state forces from the scene) with every block applied in order. A setup
// with a controller (ControllerBlock, controller_block.h) is simulated in
// closed loop and differentiated through the controller. Its
// materials are set on the simulator when they change; changed state-force
// parameters rebuild the simulator.
//
// Derivatives, exact to the simulator's tolerances:
//  - Jacobian rows (Evaluate with a jacobian), by the DerivativeMode:
//    forward mode is one Simulator::Tangents pass with one direction per
//    parameter (all directions share each step's linearisation); reverse
//    mode is one Simulator::Backward pass per row over the rollout truncated
//    after the row's last state (Rollout::Truncated: a row at state k costs k
//    adjoint steps). kAuto uses forward mode when it is available and the
//    parameters are fewer than the rows asked for. Forward mode is available
//    unless a block does not support it (ParameterBlock::SupportsForwardMode;
//    every block of the library does, state-force parameters included).
//  - Gradients of weighted sums of rows (Gradient): one Backward pass over
//    the rollout truncated after the last state a weighted row reads.
// Jacobian rows and the last gradient are cached per point (and so are their
// failures: a failed Jacobian is not recomputed at the same point).
//
// Failures: the evaluation methods never throw. A failed rollout (SolverError),
// a rejected setup (InvalidInputError, e.g. values outside a material's
// range), a non-finite value or a failed derivative makes them return false;
// the reason is in statistics().last_error, in the form
// "<stage> failed (<solver status>): <message>" (SolverError),
// "<stage> rejected: <message>" (InvalidInputError) or "<stage> error:
// <message>", with <stage> one of rollout, values, Jacobian, gradient.
//
// Thread safety: the evaluation methods are serialised by an internal mutex;
// what they copy out is consistent. RolloutAt's pointer is valid until the
// next evaluation at another point. The configuration methods (AddBlock,
// AddFunctional, Set*) must not run concurrently with anything.
#pragma once

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "diffpd/rollout.h"
#include "diffpd/scene.h"
#include "diffpd/simulator.h"
#include "diffpd/solver_options.h"
#include "diffpd/solvers/core/parameter_block.h"
#include "diffpd/solvers/core/rollout_setup.h"
#include "diffpd/solvers/core/trajectory_functional.h"

namespace diffpd::solvers {

// How Jacobian rows are computed (see the file comment).
enum class DerivativeMode {
  kAuto,     // forward if available and the parameters are fewer than the rows asked for, else reverse
  kForward,  // one tangent pass; evaluation fails where forward mode is not available
  kReverse,  // one adjoint pass per row
};
// "auto", "forward", "reverse".
const char* ToString(DerivativeMode mode);

// Counters and timings since construction or ResetStatistics().
struct RolloutStatistics {
  long rollouts = 0;            // forward simulations (new parameter points)
  long failed_rollouts = 0;     // of which failed (simulation or values)
  long jacobians = 0;           // Jacobian computations (rows at a point, one mode)
  long gradients = 0;           // gradients of weighted rows (one adjoint each)
  long adjoint_passes = 0;      // Simulator::Backward calls
  long tangent_passes = 0;      // Simulator::Tangents calls
  long failures = 0;            // failed evaluations of any stage
  double forward_seconds = 0;   // wall time making setups and simulating
  double backward_seconds = 0;  // wall time in derivative passes
  std::string last_error;       // the latest failure's message
};

class RolloutFunction {
 public:
  // Rollouts of `num_steps` >= 1 steps of `scene` with `options`; the base
  // setup is the rest state, no input (activations 1 where the scene has
  // muscles), the scene's materials and state forces. Throws
  // InvalidInputError for an invalid scene or options (what Simulator
  // throws) or num_steps < 1 ("RolloutFunction: num_steps = 0 is invalid:
  // must be >= 1").
  RolloutFunction(const Scene& scene, const SolverOptions& options, int num_steps);
  ~RolloutFunction();
  RolloutFunction(const RolloutFunction&) = delete;
  RolloutFunction& operator=(const RolloutFunction&) = delete;

  // ---- what a rollout is made from -----------------------------------
  int num_steps() const { return static_cast<int>(base_.inputs.size()); }
  // The scene as given (the base values of its materials and state forces).
  const Scene& scene() const { return scene_; }
  const SolverOptions& options() const { return options_; }
  // The simulator of the latest rollout. Valid until a point with other
  // state-force parameters is evaluated (which rebuilds it).
  Simulator& simulator() { return *sim_; }
  const Simulator& simulator() const { return *sim_; }
  const RolloutSetup& base() const { return base_; }
  // Replace the base initial state and the base inputs (K entries) that the
  // blocks add to. Throw InvalidInputError: "initial state has 135 positions
  // and 5 velocities, expected 135 each", "initial state has a non-finite
  // entry", "inputs has 2 steps, expected 4".
  void SetInitialState(const State& initial);
  void SetInputs(std::vector<StepInput> inputs);

  // ---- parameters -----------------------------------------------------
  // Appends a block; returns the offset of its first parameter. Throws
  // InvalidInputError if the block is null or does not fit the rollout
  // (ParameterBlock::CheckFits).
  int AddBlock(std::unique_ptr<ParameterBlock> block);
  int num_blocks() const { return static_cast<int>(blocks_.size()); }
  const ParameterBlock& block(int b) const { return *blocks_[b].block; }
  int block_offset(int b) const { return blocks_[b].offset; }
  int num_parameters() const { return num_parameters_; }
  // The blocks' starting values and bounds, concatenated.
  VectorXd initial_parameters() const;
  VectorXd lower_bounds() const;
  VectorXd upper_bounds() const;
  // The setup at p. Throws InvalidInputError for a p of the wrong size or
  // what a block's Apply throws.
  RolloutSetup SetupAt(const Eigen::Ref<const VectorXd>& p) const;
  // ParameterBlock::FirstAffectedState of parameter j.
  int FirstAffectedState(int j) const;

  // ---- rows -------------------------------------------------------------
  // Appends a functional; returns its index (0, 1, ...). Throws
  // InvalidInputError if it is null, has no value, or reads a state beyond
  // the rollout ("functional 'late' reads state 7, outside the rollout's
  // states [0, 4]").
  int AddFunctional(std::unique_ptr<TrajectoryFunctional> functional);
  int num_functionals() const { return static_cast<int>(functionals_.size()); }
  const TrajectoryFunctional& functional(int i) const { return *functionals_[i].functional; }
  int functional_row(int i) const { return functionals_[i].row; }
  int num_rows() const { return num_rows_; }
  // The rows of functional i; all rows.
  std::vector<int> RowsOf(int i) const;
  std::vector<int> AllRows() const;
  // The latest state index row r reads.
  int LastState(int row) const;

  // ---- derivatives' mode ------------------------------------------------
  void SetDerivativeMode(DerivativeMode mode);
  DerivativeMode derivative_mode() const { return mode_; }
  // Whether forward mode covers the blocks and the scene (file comment).
  bool ForwardModeAvailable() const;
  // kForward or kReverse: what a Jacobian of `num_rows` rows is computed by.
  DerivativeMode ResolvedMode(int num_rows) const;

  // ---- evaluation (never throws; false on failure) -----------------------
  // A non-finite parameter, value, Jacobian entry or gradient entry is a
  // failure (statistics().last_error names it), never passed on.
  // Makes the cache hold the rollout at p and the values of every row.
  bool Evaluate(const Eigen::Ref<const VectorXd>& p);
  // Evaluate(p), then copies the values of `rows` into *values and, if
  // jacobian is not nullptr, their Jacobian (|rows| x N, dv_row/dp) into
  // *jacobian (values may be nullptr too).
  bool Evaluate(const Eigen::Ref<const VectorXd>& p, const std::vector<int>& rows, VectorXd* values,
                MatrixXd* jacobian);
  // gradient (N) = sum_r weights_r dv_r/dp (weights: num_rows() entries) and,
  // if value is not nullptr, *value = sum_r weights_r v_r.
  bool Gradient(const Eigen::Ref<const VectorXd>& p, const Eigen::Ref<const VectorXd>& weights, VectorXd* gradient,
                double* value = nullptr);
  // The rollout at p, or nullptr on failure.
  const Rollout* RolloutAt(const Eigen::Ref<const VectorXd>& p);

  const RolloutStatistics& statistics() const { return stats_; }
  void ResetStatistics() { stats_ = RolloutStatistics(); }

 private:
  struct Block {
    std::unique_ptr<ParameterBlock> block;
    int offset;
  };
  struct Functional {
    std::unique_ptr<TrajectoryFunctional> functional;
    int row;
  };
  struct Cache;

  bool EvaluateLocked(const Eigen::Ref<const VectorXd>& p);
  // Sets the simulator to the setup's materials and state forces.
  void PrepareSimulator(const RolloutSetup& setup);
  void ComputeRows(const std::vector<int>& missing);
  void ForwardRows(const std::vector<int>& missing);
  void ReverseRows(const std::vector<int>& missing);
  // The parameter gradient (N) of a loss gradient (sized for the full
  // rollout) that reads states 0..last only: one adjoint pass over
  // `rollout`, the cached rollout truncated after `last`.
  VectorXd PullBack(const Rollout& rollout, LossGradient loss, int last);
  // Which functional holds row r.
  int FunctionalOf(int row) const;
  void Fail(const std::string& stage, const std::exception_ptr& error);
  void Invalidate();

  Scene scene_;
  SolverOptions options_;
  std::unique_ptr<Simulator> sim_;
  StateForceParameters sim_state_forces_;  // those sim_ was built with
  RolloutSetup base_;
  std::vector<Block> blocks_;
  std::vector<int> block_of_;  // parameter -> block
  int num_parameters_ = 0;
  std::vector<Functional> functionals_;
  int num_rows_ = 0;
  DerivativeMode mode_ = DerivativeMode::kAuto;

  std::mutex mutex_;
  std::unique_ptr<Cache> cache_;
  RolloutStatistics stats_;
};

}  // namespace diffpd::solvers
