// RolloutFunction (rollout_function.h): one rollout per parameter point and
// Jacobian rows computed once per point, the choice between forward and
// reverse mode, failures reported (not thrown) with their messages, the
// simulator following the setup's materials and state forces, and the
// validation of its configuration.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "diffpd/error.h"
#include "util/expect_message.h"
#include "solvers/core/non_finite_pull_back_block.h"
#include "solvers/core/parameter_block_cases.h"

namespace diffpd::testing {
namespace {

using namespace solvers;

TEST(RolloutFunctionTest, OneRolloutPerPointAndJacobianRowsComputedOnce) {
  ParameterBlockCase c = ExternalForceCase();  // 11 parameters, 4 rows
  RolloutFunction& f = *c.function;
  ASSERT_EQ(f.num_parameters(), 11);
  ASSERT_EQ(f.num_rows(), 4);
  VectorXd v;
  MatrixXd j, j_sub;
  ASSERT_TRUE(f.Evaluate(c.point));
  ASSERT_TRUE(f.Evaluate(c.point, f.AllRows(), &v, nullptr));
  EXPECT_EQ(f.statistics().rollouts, 1);
  EXPECT_EQ(f.ResolvedMode(4), DerivativeMode::kReverse);  // 11 parameters, 4 rows
  ASSERT_TRUE(f.Evaluate(c.point, {0, 1}, nullptr, &j_sub));
  EXPECT_EQ(f.statistics().adjoint_passes, 2);
  ASSERT_TRUE(f.Evaluate(c.point, f.AllRows(), nullptr, &j));  // rows 2 and 3 only
  EXPECT_EQ(f.statistics().adjoint_passes, 4);
  ASSERT_TRUE(f.Evaluate(c.point, {3, 0}, &v, &j_sub));  // cached
  EXPECT_EQ(f.statistics().adjoint_passes, 4);
  EXPECT_EQ(f.statistics().jacobians, 2);
  EXPECT_EQ(j_sub.row(0), j.row(3));
  EXPECT_EQ(j_sub.row(1), j.row(0));
  EXPECT_EQ(v.size(), 2);
  // A gradient is one more adjoint, cached for the same weights.
  VectorXd g;
  const VectorXd w = VectorXd::LinSpaced(4, 1.0, 2.0);
  ASSERT_TRUE(f.Gradient(c.point, w, &g));
  ASSERT_TRUE(f.Gradient(c.point, w, &g));
  EXPECT_EQ(f.statistics().adjoint_passes, 5);
  EXPECT_EQ(f.statistics().gradients, 1);
  EXPECT_EQ(f.statistics().rollouts, 1);
  // Another point simulates again; returning to the first one does too.
  VectorXd other = c.point;
  other(0) += 1e-3;
  ASSERT_TRUE(f.Evaluate(other));
  ASSERT_TRUE(f.Evaluate(c.point));
  EXPECT_EQ(f.statistics().rollouts, 3);
  EXPECT_GT(f.statistics().forward_seconds, 0);
  EXPECT_GT(f.statistics().backward_seconds, 0);
  EXPECT_EQ(f.statistics().failures, 0);
}

TEST(RolloutFunctionTest, AutoModeUsesForwardForFewParametersAndManyRows) {
  ParameterBlockCase c = MaterialCase();  // 6 parameters, 4 probes + 18 marker rows
  RolloutFunction& f = *c.function;
  ASSERT_TRUE(f.ForwardModeAvailable());
  EXPECT_EQ(f.ResolvedMode(f.num_rows()), DerivativeMode::kForward);
  EXPECT_EQ(f.ResolvedMode(4), DerivativeMode::kReverse);
  MatrixXd j;
  ASSERT_TRUE(f.Evaluate(c.point, f.AllRows(), nullptr, &j));
  EXPECT_EQ(f.statistics().tangent_passes, 1);
  EXPECT_EQ(f.statistics().adjoint_passes, 0);
  f.SetDerivativeMode(DerivativeMode::kReverse);
  EXPECT_EQ(f.ResolvedMode(f.num_rows()), DerivativeMode::kReverse);
}

TEST(RolloutFunctionTest, ForwardAndReverseJacobiansAgreeForEveryMethod) {
  // The two-region beam thrown sideways: base and region materials and the
  // initial velocity as parameters, the probes as rows.
  for (Method method : {Method::kNewtonCholesky, Method::kPdLbfgs, Method::kSemiImplicit}) {
    const Scene scene = TwoRegionBeamScene();
    SolverOptions options = TightOptions(method);
    const bool explicit_steps = method == Method::kSemiImplicit;
    if (!explicit_steps) options.time_step = 0.01;
    RolloutFunction f(scene, options, explicit_steps ? 60 : 6);
    f.AddBlock(std::make_unique<MaterialBlock>(std::vector<MaterialBlock::Entry>{MaterialField::kYoungsModulus,
                                                                                 MaterialField::kPoissonsRatio,
                                                                                 {MaterialField::kYoungsModulus, 0},
                                                                                 {MaterialField::kPoissonsRatio, 0},
                                                                                 {MaterialField::kDensity, 1}},
                                               scene));
    std::vector<int> all(scene.mesh.num_vertices());
    for (int i = 0; i < scene.mesh.num_vertices(); ++i) all[i] = i;
    f.AddBlock(std::make_unique<InitialStateBlock>(InitialStateBlock::kVelocity, all));
    AddProbes(&f);
    VectorXd p(8);
    p << 1.7e5, 0.37, 6e4, 0.32, 900, 0.01, -0.02, 0.03;
    MatrixXd forward, reverse;
    f.SetDerivativeMode(DerivativeMode::kForward);
    ASSERT_TRUE(f.Evaluate(p, f.AllRows(), nullptr, &forward)) << f.statistics().last_error;
    f.SetDerivativeMode(DerivativeMode::kReverse);
    ASSERT_TRUE(f.Evaluate(p, f.AllRows(), nullptr, &reverse)) << f.statistics().last_error;
    for (int r = 0; r < f.num_rows(); ++r) {
      const double scale = reverse.row(r).cwiseAbs().maxCoeff();
      ASSERT_GT(scale, 0.0);
      EXPECT_LE((forward.row(r) - reverse.row(r)).cwiseAbs().maxCoeff(), 1e-8 * scale)
          << ToString(method) << " row " << r;
    }
    for (int j = 0; j < f.num_parameters(); ++j)
      EXPECT_GT(reverse.col(j).cwiseAbs().maxCoeff(), 0.0) << ToString(method) << " parameter " << j;
  }
}

// A block that declares no forward mode: the state-force block's values and
// pull-back, without its push-forward.
class ReverseOnlyBlock : public ParameterBlock {
 public:
  explicit ReverseOnlyBlock(std::unique_ptr<ParameterBlock> inner)
      : ParameterBlock(inner->size()), inner_(std::move(inner)) {
    SetInitial(inner_->initial());
  }
  std::string name() const override { return "reverse_only"; }
  void CheckFits(const Scene& scene, int num_steps) const override { inner_->CheckFits(scene, num_steps); }
  void Apply(const Eigen::Ref<const VectorXd>& values, RolloutSetup* setup) const override {
    inner_->Apply(values, setup);
  }
  void PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                Eigen::Ref<VectorXd> out) const override {
    inner_->PullBack(values, grad, out);
  }
  int FirstAffectedState(int j) const override { return inner_->FirstAffectedState(j); }
  bool SupportsForwardMode() const override { return false; }
  void PushForward(const Eigen::Ref<const VectorXd>& values, int j, const RolloutSetup& setup,
                   InputDirection* direction) const override {
    ADD_FAILURE() << "PushForward of a block without forward mode";
  }

 private:
  std::unique_ptr<ParameterBlock> inner_;
};

TEST(RolloutFunctionTest, ForwardModeCoversStateForcesAndIsRefusedForABlockWithoutIt) {
  ParameterBlockCase c = StateForceCase();
  EXPECT_TRUE(c.function->ForwardModeAvailable());
  EXPECT_EQ(c.function->ResolvedMode(1000), DerivativeMode::kForward);
  RolloutFunction f(c.function->scene(), c.function->options(), c.function->num_steps());
  f.AddBlock(std::make_unique<ReverseOnlyBlock>(
      std::make_unique<StateForceBlock>(std::vector<StateForceBlock::Entry>{StateForceField::kThrust}, f.scene())));
  AddProbes(&f);
  EXPECT_FALSE(f.ForwardModeAvailable());
  EXPECT_EQ(f.ResolvedMode(1000), DerivativeMode::kReverse);
  f.SetDerivativeMode(DerivativeMode::kForward);
  MatrixXd j;
  VectorXd point = VectorXd::Constant(1, 0.6);
  EXPECT_FALSE(f.Evaluate(point, f.AllRows(), nullptr, &j));
  EXPECT_EQ(f.statistics().last_error,
            "Jacobian rejected: forward mode does not cover this rollout (a parameter block without forward mode); "
            "use DerivativeMode::kReverse or kAuto");
  // The failure is remembered for the point, the values are not lost.
  EXPECT_FALSE(f.Evaluate(point, f.AllRows(), nullptr, &j));
  EXPECT_EQ(f.statistics().failures, 1);
  VectorXd v;
  EXPECT_TRUE(f.Evaluate(point, f.AllRows(), &v, nullptr));
}

// A functional that fails: SolverError, or a NaN value.
class FailingFunction : public TrajectoryFunction {
 public:
  explicit FailingFunction(bool nan) : nan_(nan) {}
  std::string name() const override { return "failing"; }
  int LastState(int num_steps) const override { return num_steps; }
  double Value(const Rollout& r) const override {
    if (nan_) return std::numeric_limits<double>::quiet_NaN();
    throw SolverError(SolverStatus::kNonFinite, "bad loss");
  }
  void AddGradient(const Rollout& r, double weight, LossGradient* loss) const override {}

 private:
  bool nan_;
};

TEST(RolloutFunctionTest, FailuresReturnFalseWithTheReasonAndLaterPointsEvaluate) {
  // PD with at most 3 iterations per step cannot follow a large tip force.
  Scene scene = SmallBeamScene();
  SolverOptions options = TightOptions(Method::kPd);
  options.max_iterations = 3;
  RolloutFunction pd(scene, options, 3);
  std::vector<ExternalForceBlock::Channel> channels(1);
  channels[0] = {NodesAtXMax(scene.mesh), Vec3::UnitZ(), std::make_unique<PerStepSignal>(3)};
  pd.AddBlock(std::make_unique<ExternalForceBlock>(std::move(channels)));
  EXPECT_FALSE(pd.Evaluate(VectorXd::Constant(3, 5.0)));
  EXPECT_EQ(pd.statistics().failed_rollouts, 1);
  EXPECT_EQ(pd.statistics().last_error.rfind("rollout failed (maximum number of iterations reached): ", 0), 0u)
      << pd.statistics().last_error;
  EXPECT_EQ(pd.RolloutAt(VectorXd::Constant(3, 5.0)), nullptr);
  EXPECT_EQ(pd.statistics().rollouts, 1);  // the failed point is not simulated again

  RolloutFunction f(scene, TightOptions(Method::kNewtonCholesky), 3);
  f.AddBlock(std::make_unique<MaterialBlock>(
      std::vector<MaterialBlock::Entry>{MaterialField::kYoungsModulus, MaterialField::kPoissonsRatio}, scene));
  EXPECT_FALSE(f.Evaluate(Eigen::Vector2d(2e5, 0.5)));
  EXPECT_EQ(f.statistics().last_error,
            "rollout rejected: poissons_ratio = 0.5 is invalid: must be finite and in (-1, 0.5)");
  EXPECT_FALSE(f.Evaluate(Eigen::Vector2d(std::nan(""), 0.4)));
  EXPECT_EQ(f.statistics().last_error, "rollout rejected: parameter 0 = nan is not finite");
  VectorXd v;
  EXPECT_FALSE(f.Evaluate(Eigen::Vector3d(2e5, 0.4, 1e3), {}, &v, nullptr));
  EXPECT_EQ(f.statistics().last_error, "rollout rejected: the parameter vector has 3 entries, expected 2");
  EXPECT_TRUE(f.Evaluate(Eigen::Vector2d(2e5, 0.4)));

  f.AddFunctional(std::make_unique<FailingFunction>(false));
  EXPECT_FALSE(f.Evaluate(Eigen::Vector2d(2e5, 0.4)));
  EXPECT_EQ(f.statistics().last_error, "values failed (non-finite value): bad loss");
  RolloutFunction g(scene, TightOptions(Method::kNewtonCholesky), 3);
  g.AddFunctional(std::make_unique<FailingFunction>(true));
  EXPECT_FALSE(g.Evaluate(VectorXd()));
  EXPECT_EQ(g.statistics().last_error, "values rejected: functional 'failing' value 0 = nan is not finite");
  RolloutFunction h(scene, TightOptions(Method::kNewtonCholesky), 3);
  h.AddFunctional(std::make_unique<PointCoordinate>(NodePoint(45, 44), 2, Vec3::UnitZ()));
  EXPECT_FALSE(h.Evaluate(VectorXd(), {1}, &v, nullptr));
  EXPECT_EQ(h.statistics().last_error, "values rejected: row 1 is out of range [0, 1)");
}

TEST(RolloutFunctionTest, ANonFiniteJacobianOrGradientEntryIsAFailedEvaluationNotPassedOn) {
  Scene scene = SmallBeamScene();
  RolloutFunction f(scene, TightOptions(Method::kNewtonCholesky), 3);
  f.AddBlock(std::make_unique<NonFinitePullBackBlock>(std::make_unique<MaterialBlock>(
      std::vector<MaterialBlock::Entry>{MaterialField::kYoungsModulus, MaterialField::kPoissonsRatio}, scene)));
  f.AddFunctional(std::make_unique<PointCoordinate>(NodePoint(45, 44), 2, Vec3::UnitZ()));
  const Eigen::Vector2d p(2e5, 0.4);
  VectorXd values;
  MatrixXd jacobian;
  EXPECT_TRUE(f.Evaluate(p, f.AllRows(), &values, nullptr));  // the values are finite
  EXPECT_TRUE(values.allFinite());
  EXPECT_FALSE(f.Evaluate(p, f.AllRows(), &values, &jacobian));
  EXPECT_EQ(f.statistics().last_error,
            "Jacobian failed (non-finite value): row 0 (functional 'point_coordinate' value 0): the derivative with "
            "respect to parameter 0 = nan is not finite");
  EXPECT_FALSE(f.Evaluate(p, f.AllRows(), &values, &jacobian));  // and stays failed at this point
  VectorXd gradient;
  EXPECT_FALSE(f.Gradient(p, VectorXd::Ones(1), &gradient));
  EXPECT_EQ(f.statistics().last_error,
            "gradient failed (non-finite value): the derivative with respect to parameter 0 = nan is not finite");
}

TEST(RolloutFunctionTest, TheSimulatorFollowsTheSetupsMaterialsAndStateForces) {
  // A damped beam with a soft region: damping and the region's E as
  // parameters; each rollout equals a fresh simulation of the scene with
  // those values.
  Scene scene = TwoRegionBeamScene();
  scene.linear_damping = 0.5;
  const SolverOptions options = TightOptions(Method::kNewtonCholesky);
  RolloutFunction f(scene, options, 4);
  f.AddBlock(std::make_unique<MaterialBlock>(std::vector<MaterialBlock::Entry>{{MaterialField::kYoungsModulus, 0, 1e5}},
                                             scene));
  f.AddBlock(
      std::make_unique<StateForceBlock>(std::vector<StateForceBlock::Entry>{StateForceField::kLinearDamping}, scene));
  EXPECT_EQ(f.initial_parameters(), Eigen::Vector2d(scene.material_regions[0].material.youngs_modulus / 1e5, 0.5));
  for (const Eigen::Vector2d& p : {Eigen::Vector2d(0.3, 2.0), Eigen::Vector2d(0.7, 2.0), Eigen::Vector2d(0.7, 0.1)}) {
    const Rollout* r = f.RolloutAt(p);
    ASSERT_NE(r, nullptr) << f.statistics().last_error;
    Scene expected = scene;
    expected.material_regions[0].material.youngs_modulus = p(0) * 1e5;
    expected.linear_damping = p(1);
    Simulator sim(expected, options);
    const Rollout fresh = sim.Simulate(sim.RestState(), std::vector<StepInput>(4));
    const VectorXd x_end = r->states.back().x;
    EXPECT_LE((x_end - fresh.states.back().x).cwiseAbs().maxCoeff(), 1e-12) << p.transpose();
    // (not the rollout at the scene's own values)
    EXPECT_GT((x_end - f.RolloutAt(f.initial_parameters())->states.back().x).cwiseAbs().maxCoeff(), 1e-6);
  }
}

TEST(RolloutFunctionTest, BaseSetupHasRestActivationsForMuscles) {
  ParameterBlockCase c = ActivationCase();
  for (const StepInput& in : c.function->base().inputs) EXPECT_EQ(in.activation, VectorXd::Ones(2));
  // The channels' coefficients start at a rest signal.
  EXPECT_EQ(c.function->initial_parameters().head(5), VectorXd::Ones(5));
  EXPECT_EQ(c.function->initial_parameters().tail(3), Eigen::Vector3d(1, 0, 0));
}

TEST(RolloutFunctionTest, BadConfigurationIsRefusedWithAMessage) {
  const Scene scene = SmallBeamScene();
  const SolverOptions options = TightOptions(Method::kNewtonCholesky);
  EXPECT_EQ(MessageOf<InvalidInputError>([&] { RolloutFunction(scene, options, 0); }),
            "RolloutFunction: num_steps = 0 is invalid: must be >= 1");
  RolloutFunction f(scene, options, 4);
  const int n = scene.mesh.num_dofs();
  State s = f.base().initial;
  s.v.resize(5);
  EXPECT_EQ(MessageOf<InvalidInputError>([&] { f.SetInitialState(s); }), "initial state has " + std::to_string(n) +
                                                                             " positions and 5 velocities, expected " +
                                                                             std::to_string(n) + " each");
  s = f.base().initial;
  s.x(0) = std::numeric_limits<double>::infinity();
  EXPECT_EQ(MessageOf<InvalidInputError>([&] { f.SetInitialState(s); }), "initial state has a non-finite entry");
  EXPECT_EQ(MessageOf<InvalidInputError>([&] { f.SetInputs(std::vector<StepInput>(2)); }),
            "inputs has 2 steps, expected 4");
  EXPECT_EQ(MessageOf<InvalidInputError>([&] { f.AddBlock(nullptr); }), "RolloutFunction: the parameter block is null");
  EXPECT_EQ(MessageOf<InvalidInputError>([&] {
              f.AddBlock(std::make_unique<InitialStateBlock>(InitialStateBlock::kVelocity, std::vector<int>{1000}));
            }),
            "initial_velocity: node 1000 is out of range: the mesh has 45 nodes");
  EXPECT_EQ(MessageOf<InvalidInputError>([&] {
              f.AddFunctional(std::make_unique<PointCoordinate>(NodePoint(45, 0), 7, Vec3::UnitZ(), "late"));
            }),
            "functional 'late' reads state 7, outside the rollout's states [0, 4]");
  EXPECT_EQ(MessageOf<InvalidInputError>([&] { f.AddFunctional(nullptr); }), "RolloutFunction: the functional is null");
  EXPECT_EQ(f.num_blocks(), 0);
  EXPECT_EQ(f.num_functionals(), 0);
  EXPECT_EQ(MessageOf<InvalidInputError>([&] { f.SetupAt(VectorXd::Zero(2)); }),
            "the parameter vector has 2 entries, expected 0");
}

}  // namespace
}  // namespace diffpd::testing
