// The shared simulation behind the Ceres calibration adapters: parameter
// blocks in, a differentiable rollout, captured-marker residuals and their
// exact Jacobian out, cached per evaluation point.
//
//   CalibrationSetup setup;
//   setup.scene = ...;  setup.solver = ...;  setup.motion = ReadCapturedMotion("m.csv");
//   CalibrationModel model(setup);
//   double material[2];  model.InitialMaterialBlock(material);   // {E, nu}
//   // then MarkerCostFunction / RolloutEvaluationCallback / RolloutLossFunction
//
// Parameter blocks, in this order (a block is present only if non-empty):
//  - the material block: the values of `setup.fitted` (base material,
//    Scene::material) then of `setup.fitted_regions` (per material region,
//    Scene::material_regions) in physical units (Pa, 1, kg/m^3), e.g.
//    {E, nu, E_region0}; the parameters not listed stay at their values in
//    setup.scene. Positivity and log-space steps, intervals:
//    CoordinateManifold (coordinate_manifold.h); ranges also by
//    ceres::Problem::SetParameterLower/UpperBound.
//  - the input block: `setup.input_parameters` (initial state, forces), e.g.
//    LinearInputParameters below.
// Residuals: for each captured sample s (in file order) and axis d,
//   r[3 s + d] = w_sd (simulated_sd - captured_sd)
// with the simulated position interpolated in time (MarkerObservations).
//
// The Jacobian is exact: forward mode (Simulator::Tangents, one tangent per
// scalar parameter, all solved together per step) or reverse mode
// (Simulator::Backward, one adjoint per residual row over the steps that row
// depends on). Forward mode pays when parameters are few and residuals many.
#pragma once

#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "diffpd/captured_motion.h"
#include "diffpd/rollout.h"
#include "diffpd/scene.h"
#include "diffpd/simulator.h"
#include "diffpd/solver_options.h"
#include "diffpd/tangent_rollout.h"

namespace diffpd::solvers {

enum class MaterialParameter { kYoungsModulus, kPoissonsRatio, kDensity };
// "youngs_modulus", "poissons_ratio", "density".
const char* ToString(MaterialParameter parameter);

// One parameter of one material region: Scene::material_regions[region].
struct RegionParameter {
  int region = 0;  // in [0, scene.material_regions.size())
  MaterialParameter parameter = MaterialParameter::kYoungsModulus;
};

// Scene parameters that act through a rollout's differentiable inputs
// (initial state, per-step external forces and muscle activations).
// Implementations must be pure functions of p.
class InputParameters {
 public:
  virtual ~InputParameters() = default;
  // Number of scalar parameters (>= 1).
  virtual int size() const = 0;
  // Modifies the base initial state and inputs (K steps, each external force
  // 3n or empty) for parameters p (size() values) and, if directions is not
  // nullptr, sets it to size() directions, (*directions)[j] = d(inputs)/dp_j.
  // Throws InvalidInputError for p outside the domain (Evaluate then fails).
  virtual void Apply(const double* p, State* initial, std::vector<StepInput>* inputs,
                     std::vector<InputDirection>* directions) const = 0;
};

// Inputs affine in p (q parameters):
//   x0 += X p,  v0 += V p,  f_k += F p for steps force_begin <= k < force_end.
// A basis may be empty (0 x 0); non-empty ones are 3n x q.
class LinearInputParameters : public InputParameters {
 public:
  // Throws InvalidInputError if no basis is given, the non-empty bases do not
  // have the same number of columns, or a basis or the step range is
  // invalid ("force_begin = 3, force_end = 2 is invalid: need 0 <= begin <= end").
  LinearInputParameters(MatrixXd position_basis, MatrixXd velocity_basis, MatrixXd force_basis = MatrixXd(),
                        int force_begin = 0, int force_end = 0);
  // v0 += (p0, p1, p2) at every node: an unknown rigid initial velocity (m/s).
  static LinearInputParameters UniformInitialVelocity(int num_nodes);

  int size() const override { return size_; }
  void Apply(const double* p, State* initial, std::vector<StepInput>* inputs,
             std::vector<InputDirection>* directions) const override;

 private:
  MatrixXd position_, velocity_, force_;
  int force_begin_, force_end_;
  int size_ = 0;
};

enum class JacobianMode {
  kForward,  // tangents: one per scalar parameter, all per step together
  kReverse,  // adjoints: one per residual row
};

struct CalibrationSetup {
  // The simulated scene; its material holds the values of the parameters not
  // fitted and the starting values of InitialMaterialBlock().
  Scene scene;
  SolverOptions solver;
  CapturedMotion motion;
  // Base-material parameters in the material block, in this order (may be
  // empty when fitted_regions or input_parameters is set). No repetitions.
  std::vector<MaterialParameter> fitted = {MaterialParameter::kYoungsModulus, MaterialParameter::kPoissonsRatio};
  // Per-region parameters appended to the material block after `fitted`, in
  // this order (default: none). No repetitions; regions in range.
  std::vector<RegionParameter> fitted_regions;
  // Base initial state (default: the scene's rest state) and per-step inputs
  // (empty: none; else num_steps entries).
  std::optional<State> initial;
  std::vector<StepInput> inputs;
  // Rollout length; 0: just enough steps to reach the latest sample.
  int num_steps = 0;
  // Optional input block.
  std::shared_ptr<const InputParameters> input_parameters;
  JacobianMode jacobian = JacobianMode::kForward;
};

// Counters and timings since construction (or ResetStatistics()).
struct CalibrationStatistics {
  int rollouts = 0;             // forward simulations (new evaluation points)
  int jacobians = 0;            // Jacobian evaluations
  int gradients = 0;            // scalar-loss gradients (one adjoint each)
  int failures = 0;             // points where the rollout or a derivative failed
  double forward_seconds = 0;   // simulating
  double backward_seconds = 0;  // tangents / adjoints
  std::string last_error;       // message of the latest failure
};

// A scalar loss of a rollout: returns L and sets dL/dx_k, dL/dv_k (gradient
// is sized for the rollout's steps with empty entries on entry).
using TrajectoryLoss = std::function<double(const Rollout& rollout, LossGradient* gradient)>;

class CalibrationModel {
 public:
  // Validates the setup (InvalidInputError: the scene, the options, the
  // markers against the mesh, samples beyond num_steps, sizes of initial
  // state and inputs, a repeated `fitted` entry ("fitted lists density
  // twice"), a region parameter out of range ("fitted_regions[1]: region 2
  // is out of range [0, 2)") or repeated ("fitted_regions lists
  // youngs_modulus of region 0 twice"), nothing to fit).
  explicit CalibrationModel(CalibrationSetup setup);
  CalibrationModel(const CalibrationModel&) = delete;
  CalibrationModel& operator=(const CalibrationModel&) = delete;

  const CalibrationSetup& setup() const { return setup_; }
  const MarkerObservations& observations() const { return observations_; }
  int num_steps() const { return num_steps_; }
  int num_residuals() const { return 3 * observations_.num_samples(); }
  // Sizes of the parameter blocks, in order (see the file comment).
  const std::vector<int>& parameter_block_sizes() const { return block_sizes_; }
  // Index of the material / input block, or -1 if absent.
  int material_block() const { return material_block_; }
  int input_block() const { return input_block_; }
  // Fills the material block with setup.scene's values (base material, then
  // regions).
  void InitialMaterialBlock(double* block) const;
  // The base material at a material block (the others from the setup).
  MaterialParameters MaterialAt(const double* block) const;
  // Material region `region`'s material at a material block (the parameters
  // not in fitted_regions from the setup). Throws InvalidInputError for a
  // region out of range.
  MaterialParameters RegionMaterialAt(const double* block, int region) const;
  // Samples grouped by equal time, in order of time: one group per frame.
  std::vector<std::vector<int>> SamplesByFrame() const;

  // Makes the cache current for the parameter values (one pointer per block)
  // and, if `jacobian`, the Jacobian too. Returns false, never throws, when
  // the rollout or its derivative fails (SolverError, or InvalidInputError
  // for values outside the material's range); the reason is in
  // statistics().last_error. Thread-safe; the accessors below read the cache
  // and are valid until the next call.
  bool Evaluate(const double* const* parameters, bool jacobian);
  const VectorXd& residuals() const { return residuals_; }
  // num_residuals() x block size, column-major.
  const MatrixXd& jacobian(int block) const { return jacobians_[block]; }
  const Rollout& rollout() const { return rollout_; }

  // Scalar loss and its gradient w.r.t. all parameters (blocks concatenated;
  // gradient may be nullptr) by one adjoint. An empty loss means the
  // least-squares loss 1/2 |r|^2 of the residuals. False on failure.
  bool EvaluateLoss(const double* const* parameters, const TrajectoryLoss& loss, double* cost, double* gradient);

  const CalibrationStatistics& statistics() const { return stats_; }
  void ResetStatistics() { stats_ = CalibrationStatistics(); }

 private:
  bool Prepare(const double* const* parameters);
  bool ComputeJacobian();
  void ForwardJacobian();
  void ReverseJacobian();
  // Parameter gradient (concatenated blocks) of a rollout gradient whose
  // rollout covered steps 0..last_step.
  VectorXd ParameterGradient(const RolloutGradient& g, int last_step) const;
  void Fail(const std::string& message);

  CalibrationSetup setup_;
  std::unique_ptr<Simulator> sim_;
  MarkerObservations observations_;
  int num_steps_ = 0;
  std::vector<int> block_sizes_;
  int material_block_ = -1, input_block_ = -1;
  int num_parameters_ = 0;

  std::mutex mutex_;
  bool have_point_ = false, point_ok_ = false, have_jacobian_ = false, jacobian_ok_ = false;
  std::vector<double> point_;  // concatenated parameter values of the cache
  Rollout rollout_;
  std::vector<InputDirection> input_directions_;
  VectorXd residuals_;
  std::vector<MatrixXd> jacobians_;
  CalibrationStatistics stats_;
};

}  // namespace diffpd::solvers
