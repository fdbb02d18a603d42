// Closed-loop rollouts (Simulate with a controller) and their gradients
// (Backward with the controller): a controller that ignores the state gives
// the open-loop rollout and gradients bit for bit; a network controller of
// muscle strips on a small swimmer in water (quad hydrodynamics) has
// gradients w.r.t. its weights, the initial state and Young's modulus that
// match central differences of whole closed-loop rollouts, for PD-LBFGS and
// Newton-Cholesky; and the closed-loop entry points check their inputs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "diffpd/error.h"
#include "diffpd/simulator.h"
#include "diffpd/strip_network_controller.h"
#include "test_scenes.h"
#include "util/central_difference.h"
#include "util/expect_message.h"

namespace diffpd {
namespace {

using testing::RandomVector;

// A 4 x 1 x 2 hex bar (0.4 x 0.1 x 0.2 m) in still water, free, with two
// muscle strips along x (bottom and top layer, root at x = 0).
struct Swimmer {
  Scene scene;
  std::vector<std::vector<int>> strips;
};

Swimmer MakeSwimmer() {
  Swimmer s;
  s.scene.mesh = testing::BoxHexMesh(4, 1, 2, 0.4, 0.1, 0.2);
  s.scene.material = MaterialParameters{1e5, 0.4, 1e3};
  s.scene.energies = {ElasticEnergy::kPdCorotated};
  QuadHydrodynamics water;
  water.quads = BoundaryQuads(s.scene.mesh);
  s.scene.quad_hydrodynamics = water;
  std::vector<MuscleStrip> strips(2);
  for (int layer = 0; layer < 2; ++layer) {
    for (int e = 0; e < s.scene.mesh.num_elements(); ++e) {
      Vec3 c = Vec3::Zero();
      for (int a = 0; a < 8; ++a) c += s.scene.mesh.vertices.col(s.scene.mesh.elements(a, e)) / 8;
      if ((c.z() > 0.1) == (layer == 1)) strips[layer].elements.push_back(e);
    }
    std::sort(strips[layer].elements.begin(), strips[layer].elements.end(), [&](int a, int b) {
      return s.scene.mesh.vertices(0, s.scene.mesh.elements(0, a)) <
             s.scene.mesh.vertices(0, s.scene.mesh.elements(0, b));
    });
    strips[layer].fiber = Vec3::UnitX();
    strips[layer].stiffness = 1e5;
  }
  s.strips = AddMuscleStrips(&s.scene, strips);
  return s;
}

StripNetworkController MakeController(const Swimmer& s, std::uint64_t seed) {
  const NodeObservation obs{0, {4, 9, 14}};
  Mlp mlp({obs.size(), 8, 1}, MlpNonlinearity::kTanh, MlpNonlinearity::kTanh);
  mlp.InitializeOrthogonal(seed, 5.0 / 3.0);
  const int muscles = static_cast<int>(s.scene.muscles.size());
  return StripNetworkController(mlp, obs, MuscleDelayLine(s.strips, muscles), {{0, -1}, {0, 1}},
                                s.scene.mesh.num_vertices());
}

// A moving, deformed start so that the water pushes from the first step,
// every face's velocity well away from its plane (the one-sided faces'
// switch).
State SwimmingStart(const Simulator& sim) {
  State s = sim.RestState();
  for (int i = 0; i < s.x.size() / 3; ++i) {
    s.x(3 * i + 2) += 0.05 * s.x(3 * i) * s.x(3 * i);
    s.v(3 * i) = 0.1;
    s.v(3 * i + 1) = 0.07 + 0.1 * s.x(3 * i + 2);
    s.v(3 * i + 2) = 0.3 * s.x(3 * i) + 0.04;
  }
  return s;
}

// The smallest |n . d| over the quads at a state: how close a face is to
// switching (the force jumps there, and differences across it mean nothing).
double MinFaceCosine(const Scene& scene, const State& s) {
  double least = INFINITY;
  const Eigen::Matrix4Xi& q = scene.quad_hydrodynamics->quads;
  for (int f = 0; f < q.cols(); ++f) {
    Vec3 p[4], v = Vec3::Zero();
    for (int c = 0; c < 4; ++c) {
      p[c] = s.x.segment<3>(3 * q(c, f));
      v += s.v.segment<3>(3 * q(c, f)) / 4;
    }
    const Vec3 n = ((p[1] - p[0]).cross(p[2] - p[1]) + (p[2] - p[0]).cross(p[3] - p[2])).normalized();
    least = std::min(least, std::abs(n.dot(v)) / v.norm());
  }
  return least;
}

// L = sum_k a_k . x_k + b_k . v_k with seeded random weights.
LossGradient RandomLoss(int steps, int n) {
  std::mt19937_64 rng(17);
  LossGradient loss(steps);
  for (int k = 1; k <= steps; ++k) {
    loss.dx[k] = RandomVector(n, &rng, 1.0);
    loss.dv[k] = RandomVector(n, &rng, 0.1);
  }
  return loss;
}

double LossOf(const Rollout& r, const LossGradient& loss) {
  double l = 0;
  for (int k = 0; k <= r.num_steps(); ++k) {
    if (loss.dx[k].size()) l += loss.dx[k].dot(r.states[k].x);
    if (loss.dv[k].size()) l += loss.dv[k].dot(r.states[k].v);
  }
  return l;
}

// Open-loop activations as a controller: theta holds the activation of
// every muscle at every step; it reads neither the state nor a memory.
class ScheduleController : public Controller {
 public:
  ScheduleController(int steps, int muscles, VectorXd theta) : steps_(steps), muscles_(muscles), theta_(theta) {}
  std::unique_ptr<Controller> Clone() const override { return std::make_unique<ScheduleController>(*this); }
  int num_parameters() const override { return steps_ * muscles_; }
  VectorXd parameters() const override { return theta_; }
  void SetParameters(const VectorXd& p) override { theta_ = p; }
  void Act(int step, const State&, const VectorXd&, ControlAction* action, VectorXd* next_memory) const override {
    action->activation = theta_.segment(step * muscles_, muscles_);
    next_memory->resize(0);
  }
  void ActVjp(int step, const State&, const VectorXd&, const ControlAction& g_action, const VectorXd&, VectorXd*,
              VectorXd*, VectorXd* g_memory, VectorXd* g_parameters) const override {
    g_memory->resize(0);
    if (g_action.activation.size()) g_parameters->segment(step * muscles_, muscles_) += g_action.activation;
  }

 private:
  int steps_, muscles_;
  VectorXd theta_;
};

class ClosedLoopGradientTest : public ::testing::TestWithParam<Method> {};

TEST_P(ClosedLoopGradientTest, StateIgnoringControllerGivesTheOpenLoopRolloutAndGradientsBitForBit) {
  const Swimmer s = MakeSwimmer();
  // One simulator per loop, each simulating then differentiating: a
  // simulator's SVDs are warm-started from its previous ones, so its results
  // depend, to rounding, on what it computed before.
  Simulator open_sim(s.scene, testing::TightOptions(GetParam()));
  Simulator closed_sim(s.scene, testing::TightOptions(GetParam()));
  const int steps = 4, muscles = static_cast<int>(s.scene.muscles.size());
  std::mt19937_64 rng(3);
  const VectorXd theta = (VectorXd::Ones(steps * muscles) + RandomVector(steps * muscles, &rng, 0.2)).eval();
  const ScheduleController schedule(steps, muscles, theta);
  std::vector<StepInput> inputs(steps);
  for (int k = 0; k < steps; ++k) inputs[k].activation = theta.segment(k * muscles, muscles);
  const State start = SwimmingStart(open_sim);
  const LossGradient loss = RandomLoss(steps, open_sim.num_dofs());
  const Rollout open = open_sim.Simulate(start, inputs);
  const RolloutGradient g_open = open_sim.Backward(open, loss);
  const Rollout closed = closed_sim.Simulate(start, schedule, steps);
  const RolloutGradient g_closed = closed_sim.Backward(closed, loss, schedule);
  ASSERT_TRUE(closed.closed_loop());
  for (int k = 0; k <= steps; ++k) {
    EXPECT_EQ(open.states[k].x, closed.states[k].x) << "step " << k;
    EXPECT_EQ(open.states[k].v, closed.states[k].v) << "step " << k;
  }
  EXPECT_EQ(g_open.x0, g_closed.x0);
  EXPECT_EQ(g_open.v0, g_closed.v0);
  EXPECT_EQ(g_open.youngs_modulus, g_closed.youngs_modulus);
  EXPECT_EQ(g_open.poissons_ratio, g_closed.poissons_ratio);
  EXPECT_EQ(g_open.density, g_closed.density);
  for (int k = 0; k < steps; ++k)
    EXPECT_EQ(g_open.activation[k], g_closed.controller_parameters.segment(k * muscles, muscles)) << "step " << k;
  EXPECT_EQ(g_closed.controller_memory.size(), 0);
  EXPECT_EQ(g_open.controller_parameters.size(), 0);
}

TEST_P(ClosedLoopGradientTest, NetworkControllerGradientsMatchCentralDifferencesOfClosedLoopRollouts) {
  const Swimmer s = MakeSwimmer();
  const SolverOptions options = testing::TightOptions(GetParam());
  Simulator sim(s.scene, options);
  const StripNetworkController controller = MakeController(s, 5);
  const int steps = 5;
  const State start = SwimmingStart(sim);
  const Rollout rollout = sim.Simulate(start, controller, steps);
  // The channel stays away from max(., 0)'s kink along the rollout, so the
  // differences see one smooth branch.
  for (int k = 0; k < steps; ++k)
    ASSERT_GT(std::abs(controller.network().Evaluate(controller.Observe(rollout.states[k]))(0)), 1e-3) << k;
  // Likewise every face stays on one side of its switch.
  for (int k = 0; k < steps; ++k) ASSERT_GT(MinFaceCosine(s.scene, rollout.states[k]), 1e-3) << k;
  const LossGradient loss = RandomLoss(steps, sim.num_dofs());
  const RolloutGradient g = sim.Backward(rollout, loss, controller);
  ASSERT_EQ(g.controller_parameters.size(), controller.num_parameters());
  ASSERT_EQ(g.controller_memory.size(), controller.memory_size());

  testing::DifferenceOptions policy;
  policy.noise = options.rel_tolerance;
  policy.rtol = 1e-6;
  std::mt19937_64 rng(23);
  // Weights: the network changes over O(1) changes of a weight.
  {
    const VectorXd d = RandomVector(controller.num_parameters(), &rng, 1.0);
    const double h = testing::CentralDifferenceStep(policy.noise, 1.0, d.cwiseAbs().maxCoeff());
    auto at = [&](double eps) {
      StripNetworkController c = controller;
      c.SetParameters(controller.parameters() + eps * d);
      return LossOf(sim.Simulate(start, c, steps), loss);
    };
    EXPECT_TRUE(
        testing::Passes(testing::CompareCentralDifference(at(h), at(-h), h, g.controller_parameters.dot(d), policy)))
        << "weights";
  }
  // Initial positions and velocities: over the element size, 0.1 m.
  {
    const VectorXd dx = RandomVector(sim.num_dofs(), &rng, 1.0), dv = RandomVector(sim.num_dofs(), &rng, 1.0);
    const double h = testing::CentralDifferenceStep(policy.noise, 0.1);
    auto at = [&](double eps) {
      State st = start;
      st.x += eps * dx;
      st.v += eps * dv;
      return LossOf(sim.Simulate(st, controller, steps), loss);
    };
    EXPECT_TRUE(
        testing::Passes(testing::CompareCentralDifference(at(h), at(-h), h, g.x0.dot(dx) + g.v0.dot(dv), policy)))
        << "initial state";
  }
  // Young's modulus, over its own size.
  {
    const double e = s.scene.material.youngs_modulus;
    const double h = testing::CentralDifferenceStep(policy.noise, e);
    auto at = [&](double eps) {
      sim.SetMaterial(MaterialParameters{e + eps, s.scene.material.poissons_ratio, s.scene.material.density});
      return LossOf(sim.Simulate(start, controller, steps), loss);
    };
    const double plus = at(h), minus = at(-h);
    sim.SetMaterial(s.scene.material);
    EXPECT_TRUE(testing::Passes(testing::CompareCentralDifference(plus, minus, h, g.youngs_modulus, policy)))
        << "Young's modulus";
  }
  // A truncated closed-loop rollout keeps its controller's memory: the
  // adjoint of a loss on the first 3 states is the same on it.
  LossGradient early(steps);
  for (int k = 0; k <= 3; ++k) early.dx[k] = loss.dx[k];
  LossGradient early_truncated(3);
  for (int k = 0; k <= 3; ++k) early_truncated.dx[k] = loss.dx[k];
  const Rollout truncated = rollout.Truncated(3);
  ASSERT_EQ(truncated.controller_memory.size(), 4u);
  const RolloutGradient g_early = sim.Backward(rollout, early, controller);
  const RolloutGradient g_truncated = sim.Backward(truncated, early_truncated, controller);
  EXPECT_LT((g_early.controller_parameters - g_truncated.controller_parameters).norm(),
            1e-8 * g_early.controller_parameters.norm());
  // The closed loop matters: the gradient of the recorded actions held
  // fixed (open loop) differs from it.
  const RolloutGradient g_open = sim.Backward(rollout, loss);
  EXPECT_GT((g_open.x0 - g.x0).norm(), 1e-3 * g.x0.norm());
}

INSTANTIATE_TEST_SUITE_P(Methods, ClosedLoopGradientTest, ::testing::Values(Method::kPdLbfgs, Method::kNewtonCholesky),
                         [](const ::testing::TestParamInfo<Method>& info) {
                           std::string name = ToString(info.param);
                           for (char& ch : name)
                             if (ch == '-') ch = '_';
                           return name;
                         });

// A controller whose action or memory has the wrong size or values.
class FaultyController : public Controller {
 public:
  enum class Fault { kActivationSize, kNonFiniteActivation, kForceSize, kMemorySize, kNonFiniteMemory };
  explicit FaultyController(Fault fault) : fault_(fault) {}
  std::unique_ptr<Controller> Clone() const override { return std::make_unique<FaultyController>(*this); }
  int num_parameters() const override { return 1; }
  VectorXd parameters() const override { return VectorXd::Constant(1, theta_); }
  void SetParameters(const VectorXd& p) override { theta_ = p(0); }
  int memory_size() const override { return 2; }
  void Act(int step, const State& state, const VectorXd&, ControlAction* action, VectorXd* next) const override {
    action->activation = VectorXd::Ones(8);
    *next = VectorXd::Zero(2);
    if (step < 1) return;
    switch (fault_) {
      case Fault::kActivationSize:
        action->activation = VectorXd::Ones(3);
        break;
      case Fault::kNonFiniteActivation:
        action->activation(1) = INFINITY;
        break;
      case Fault::kForceSize:
        action->external_force = VectorXd::Zero(5);
        break;
      case Fault::kMemorySize:
        *next = VectorXd::Zero(3);
        break;
      case Fault::kNonFiniteMemory:
        (*next)(1) = NAN;
        break;
    }
  }
  void ActVjp(int, const State&, const VectorXd&, const ControlAction&, const VectorXd&, VectorXd*, VectorXd*,
              VectorXd* g_memory, VectorXd*) const override {
    *g_memory = VectorXd::Zero(2);
  }

 private:
  Fault fault_;
  double theta_ = 0;
};

TEST(ClosedLoopInputTest, SimulateRefusesInvalidActionsMemoriesAndStepCounts) {
  const Swimmer s = MakeSwimmer();
  Simulator sim(s.scene, testing::TightOptions(Method::kPdLbfgs));
  using F = FaultyController::Fault;
  const State start = sim.RestState();
  EXPECT_THROW_MESSAGE(sim.Simulate(start, FaultyController(F::kActivationSize), 3), InvalidInputError,
                       "Simulate: the controller's action at step 1: activation has 3 entries, expected 8 (one per "
                       "muscle)");
  EXPECT_THROW_MESSAGE(sim.Simulate(start, FaultyController(F::kNonFiniteActivation), 3), InvalidInputError,
                       "Simulate: the controller's action at step 1: activation[1] = inf is invalid: must be finite");
  EXPECT_THROW_MESSAGE(sim.Simulate(start, FaultyController(F::kForceSize), 3), InvalidInputError,
                       "Simulate: the controller's action at step 1: external_force has 5 entries, expected 90 (3 x "
                       "number of nodes)");
  EXPECT_THROW_MESSAGE(sim.Simulate(start, FaultyController(F::kMemorySize), 3), InvalidInputError,
                       "Simulate: the controller's memory after step 1 has 3 entries, expected 2");
  EXPECT_THROW_MESSAGE(sim.Simulate(start, FaultyController(F::kNonFiniteMemory), 3), InvalidInputError,
                       "Simulate: the controller's memory after step 1 has a non-finite entry");
  EXPECT_THROW_MESSAGE(sim.Simulate(start, FaultyController(F::kMemorySize), -1), InvalidInputError,
                       "Simulate: steps = -1 is invalid: must be >= 0");
}

TEST(ClosedLoopInputTest, BackwardRefusesOpenLoopRolloutsAndChangedControllers) {
  const Swimmer s = MakeSwimmer();
  Simulator sim(s.scene, testing::TightOptions(Method::kPdLbfgs));
  StripNetworkController controller = MakeController(s, 5);
  const Rollout open = sim.Simulate(sim.RestState(), std::vector<StepInput>(2));
  EXPECT_THROW_MESSAGE(sim.Backward(open, LossGradient(2), controller), InvalidInputError,
                       "Backward: the rollout is open-loop (made without a controller)");
  const Rollout closed = sim.Simulate(sim.RestState(), controller, 2);
  VectorXd theta = controller.parameters();
  theta(3) += 1e-9;
  controller.SetParameters(theta);
  EXPECT_THROW_MESSAGE(sim.Backward(closed, LossGradient(2), controller), InvalidInputError,
                       "Backward: the controller's parameters differ from those the rollout was made with");
  Rollout other = closed;
  other.controller_memory.pop_back();
  EXPECT_THROW_MESSAGE(sim.Backward(other, LossGradient(2), MakeController(s, 5)), InvalidInputError,
                       "Backward: the rollout has inconsistent controller memory and inputs");
  other = closed;
  other.controller_memory[1] = VectorXd::Zero(3);
  EXPECT_THROW_MESSAGE(sim.Backward(other, LossGradient(2), MakeController(s, 5)), InvalidInputError,
                       "Backward: the rollout's controller memory has 3 entries, the controller's 8");
}

}  // namespace
}  // namespace diffpd
