// Checkpointed rollouts (checkpointed_rollout.h): the binomial schedule's
// bounds (every step advanced at most t times, at most c checkpoints held),
// gradients bit-identical to those of a stored rollout with cold SVDs
// (SolverOptions::svd_warm_start = false; muscles, state forces, frictional
// contact, horizons not a multiple of anything) and equal to the default
// (warm) stored rollout's to rounding, the streaming loss form, the memory
// bound, and the input checks' messages.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <random>

#include "diffpd/box_mesh.h"
#include "diffpd/error.h"
#include "diffpd/simulator.h"
#include "solver/checkpoint_schedule.h"
#include "test_scenes.h"
#include "util/expect_message.h"

namespace diffpd {
namespace {

using internal::BinomialRepetitions;
using internal::BinomialSplit;
using internal::FirstDescentSteps;

// Runs the schedule of checkpoint_schedule.h on l steps with s slots,
// counting per step how often it is advanced, and the most slots in use.
struct ScheduleCount {
  std::vector<int> advanced;
  long total = 0;  // advances in all
  int max_slots = 0;
  std::vector<int> reversed;  // steps in the order they are differentiated
};

void Reverse(int a, int l, int s, int used, ScheduleCount* count) {
  while (l > 1) {
    const int m = BinomialSplit(l, s);
    ASSERT_GE(m, 1);
    ASSERT_LE(m, l - 1);
    for (int k = a; k < a + m; ++k) ++count->advanced[k];
    count->total += m;
    count->max_slots = std::max(count->max_slots, used + 1);
    Reverse(a + m, l - m, s - 1, used + 1, count);
    l = m;
  }
  count->reversed.push_back(a);
}

TEST(CheckpointScheduleTest, EveryStepIsAdvancedAtMostTheBinomialBoundAndSlotsAreNotExceeded) {
  for (int slots : {1, 2, 3, 5, 48}) {
    for (int steps : {1, 2, 7, 23, 100, 1000}) {
      if (slots == 1 && steps > 100) continue;  // quadratic, slow to count
      ScheduleCount count;
      count.advanced.assign(steps, 0);
      Reverse(0, steps, slots, 0, &count);
      const int t = BinomialRepetitions(steps, slots);
      EXPECT_LE(*std::max_element(count.advanced.begin(), count.advanced.end()), t)
          << steps << " steps, " << slots << " slots";
      EXPECT_LE(count.max_slots, slots);
      ASSERT_EQ(static_cast<int>(count.reversed.size()), steps);
      for (int k = 0; k < steps; ++k) EXPECT_EQ(count.reversed[k], steps - 1 - k);
    }
  }
}

// The fewest advances that reverse l steps with s slots, by dynamic
// programming over every first split: T(1, s) = 0,
// T(l, s) = min over m of m + T(l - m, s - 1) + T(m, s).
TEST(CheckpointScheduleTest, SplitsAreOptimalAgainstDynamicProgramming) {
  const int max_steps = 60, max_slots = 5;
  const long inf = 1L << 40;
  std::vector<std::vector<long>> best(max_steps + 1, std::vector<long>(max_slots + 1, inf));
  for (int s = 0; s <= max_slots; ++s) best[1][s] = 0;
  for (int l = 2; l <= max_steps; ++l)
    for (int s = 1; s <= max_slots; ++s)
      for (int m = 1; m < l; ++m) best[l][s] = std::min(best[l][s], m + best[l - m][s - 1] + best[m][s]);
  for (int s = 1; s <= max_slots; ++s)
    for (int l = 1; l <= max_steps; ++l) {
      ScheduleCount count;
      count.advanced.assign(l, 0);
      Reverse(0, l, s, 0, &count);
      EXPECT_EQ(count.total, best[l][s]) << l << " steps, " << s << " slots";
    }
}

TEST(CheckpointScheduleTest, RepetitionsFollowTheBinomialCoefficients) {
  // beta(48, 2) = 50 * 49 / 2 = 1225, beta(48, 3) = 51 * 50 * 49 / 6 = 20825.
  EXPECT_EQ(BinomialRepetitions(1225, 48), 2);
  EXPECT_EQ(BinomialRepetitions(1226, 48), 3);
  EXPECT_EQ(BinomialRepetitions(20825, 48), 3);
  EXPECT_EQ(BinomialRepetitions(20826, 48), 4);
  EXPECT_EQ(BinomialRepetitions(1, 3), 0);
  // One slot: beta(1, t) = t + 1.
  EXPECT_EQ(BinomialRepetitions(10, 1), 9);
  const std::vector<int> chain = FirstDescentSteps(23, 3);
  EXPECT_LE(chain.size(), 3u);
  EXPECT_TRUE(std::is_sorted(chain.begin(), chain.end()));
  EXPECT_GT(chain.front(), 0);
  EXPECT_LT(chain.back(), 23);
}

// Every RolloutGradient component equal bit for bit.
void ExpectIdentical(const RolloutGradient& a, const RolloutGradient& b, const std::string& what) {
  EXPECT_EQ(a.x0, b.x0) << what;
  EXPECT_EQ(a.v0, b.v0) << what;
  EXPECT_EQ(a.youngs_modulus, b.youngs_modulus) << what;
  EXPECT_EQ(a.poissons_ratio, b.poissons_ratio) << what;
  EXPECT_EQ(a.density, b.density) << what;
  ASSERT_EQ(a.external_force.size(), b.external_force.size()) << what;
  for (size_t k = 0; k < a.external_force.size(); ++k) {
    EXPECT_EQ(a.external_force[k], b.external_force[k]) << what << " step " << k;
    EXPECT_EQ(a.activation[k], b.activation[k]) << what << " step " << k;
  }
  EXPECT_EQ(a.state_forces.linear_damping, b.state_forces.linear_damping) << what;
  EXPECT_EQ(a.state_forces.penalty_friction, b.state_forces.penalty_friction) << what;
  EXPECT_EQ(a.report.linear_iterations, b.report.linear_iterations) << what;
}

// A loss on several states: random dL/dx, dL/dv at the last state and two others.
LossGradient SomeLoss(int n, int steps, unsigned seed) {
  std::mt19937_64 rng(seed);
  LossGradient loss(steps);
  loss.dx[steps] = testing::RandomVector(n, &rng, 1.0);
  loss.dv[steps] = testing::RandomVector(n, &rng, 0.1);
  loss.dx[steps / 2] = testing::RandomVector(n, &rng, 1.0);
  loss.dv[1] = testing::RandomVector(n, &rng, 0.1);
  return loss;
}

// ||a - b|| / ||b|| over the initial state's gradient, the material's and the
// per-step forces'.
double RelativeGradientDifference(const RolloutGradient& a, const RolloutGradient& b) {
  double diff = (a.x0 - b.x0).squaredNorm() + (a.v0 - b.v0).squaredNorm();
  double norm = b.x0.squaredNorm() + b.v0.squaredNorm();
  for (const auto& [p, q] : {std::pair{a.youngs_modulus, b.youngs_modulus}, std::pair{a.density, b.density}}) {
    diff += (p - q) * (p - q);
    norm += q * q;
  }
  for (size_t k = 0; k < a.external_force.size(); ++k) {
    diff += (a.external_force[k] - b.external_force[k]).squaredNorm();
    norm += b.external_force[k].squaredNorm();
  }
  return std::sqrt(diff / norm);
}

// Simulate + Backward (and Tangents) with cold SVDs against
// SimulateCheckpointed + Backward (and Tangents) on one scene: bit for bit;
// against the default stored rollout (warm SVDs): within `warm_tolerance`
// (relative), the forward's solves stopping at their tolerance from other
// rounding.
void CheckIdenticalGradients(const Scene& scene, const SolverOptions& options, const State& start,
                             const std::vector<StepInput>& inputs, int checkpoints, const std::string& what,
                             double warm_tolerance) {
  ASSERT_TRUE(options.svd_warm_start);
  SolverOptions cold = options;
  cold.svd_warm_start = false;
  Simulator sim(scene, cold);
  const int steps = static_cast<int>(inputs.size());
  const Rollout stored = sim.Simulate(start, inputs);
  const LossGradient loss = SomeLoss(sim.num_dofs(), steps, 7);
  const RolloutGradient expected = sim.Backward(stored, loss);
  Simulator warm_sim(scene, options);
  const RolloutGradient warm = warm_sim.Backward(warm_sim.Simulate(start, inputs), loss);
  // The checkpointed rollout runs cold whatever the simulator's option.
  sim.SetOptions(options);
  CheckpointOptions c;
  c.num_checkpoints = checkpoints;
  std::vector<State> observed;
  const CheckpointedRollout r = sim.SimulateCheckpointed(start, inputs, c, [&observed](int k, const State& s) {
    EXPECT_EQ(k, static_cast<int>(observed.size()));
    observed.push_back(s);
  });
  ASSERT_EQ(static_cast<int>(observed.size()), steps + 1);
  for (int k = 0; k <= steps; ++k) ASSERT_EQ(observed[k].x, stored.states[k].x) << what << " state " << k;
  EXPECT_EQ(r.final.x, stored.states.back().x) << what;
  EXPECT_LE(static_cast<int>(r.checkpoints.size()), checkpoints) << what;
  EXPECT_TRUE(sim.options().svd_warm_start) << what;
  EXPECT_FALSE(r.options.svd_warm_start) << what;
  const RolloutGradient g = sim.Backward(r, loss);
  ExpectIdentical(g, expected, what);
  const double warm_difference = RelativeGradientDifference(g, warm);
  EXPECT_LT(warm_difference, warm_tolerance) << what;
  std::printf("%s: checkpointed vs warm stored gradient, relative difference %.2e\n", what.c_str(), warm_difference);
  // Forward mode: the same tangents as over the stored rollout, kept or streamed.
  InputDirection e = InputDirection::YoungsModulus();
  InputDirection v0;
  std::mt19937_64 rng(11);
  v0.v0 = testing::RandomVector(sim.num_dofs(), &rng, 0.1);
  const TangentRollout t_stored = sim.Tangents(stored, {e, v0});
  const TangentRollout t_kept = sim.Tangents(r, {e, v0});
  ASSERT_EQ(t_kept.num_steps(), steps) << what;
  int seen = 0;
  const TangentRollout t_streamed =
      sim.Tangents(r, {e, v0}, [&](int k, const State& s, const MatrixXd& dx, const MatrixXd& dv) {
        EXPECT_EQ(k, seen++) << what;
        EXPECT_EQ(s.x, stored.states[k].x) << what << " state " << k;
        EXPECT_EQ(dx, t_stored.dx[k]) << what << " tangent " << k;
        EXPECT_EQ(dv, t_stored.dv[k]) << what << " tangent " << k;
      });
  EXPECT_EQ(seen, steps + 1) << what;
  EXPECT_TRUE(t_streamed.dx.empty()) << what;
  for (int k = 0; k <= steps; ++k) {
    EXPECT_EQ(t_kept.dx[k], t_stored.dx[k]) << what << " tangent " << k;
    EXPECT_EQ(t_kept.dv[k], t_stored.dv[k]) << what << " tangent " << k;
  }
  EXPECT_LE(g.report.peak_states, 2 * checkpoints + 4) << what;
  EXPECT_LE(g.report.recomputed_steps, BinomialRepetitions(steps, checkpoints) * steps) << what;
  // With a checkpoint at every step nothing is recomputed.
  if (checkpoints >= steps - 1) {
    EXPECT_EQ(g.report.recomputed_steps, 0) << what;
  } else if (checkpoints < steps / 2) {
    EXPECT_GT(g.report.recomputed_steps, 0) << what;
  }
}

TEST(CheckpointedRolloutTest, MuscleBeamGradientsAreBitIdenticalToTheStoredRollout) {
  Scene scene = testing::SmallBeamScene();
  Muscle muscle;
  for (int e = 0; e < scene.mesh.num_elements(); e += 2) muscle.elements.push_back(e);
  muscle.fibers = {Vec3(1, 0, 0)};
  muscle.stiffness = 3e5;
  scene.muscles = {muscle};
  scene.linear_damping = 0.5;
  const int steps = 23;  // not a multiple of any schedule's segment
  std::vector<StepInput> inputs(steps);
  for (int k = 0; k < steps; ++k) {
    inputs[k].activation = VectorXd::Constant(1, 0.9 - 0.01 * k);
    if (k % 3 == 0) inputs[k].external_force = VectorXd::Constant(3 * scene.mesh.num_vertices(), 0.01 * k);
  }
  for (Method method : {Method::kPdLbfgs, Method::kNewtonCholesky}) {
    SolverOptions options = testing::TightOptions(method);
    options.rel_tolerance = 1e-8;  // the backward's tolerance follows the forward's residuals
    options.backward_rel_tolerance = 0;
    Simulator probe(scene, options);
    const State start = testing::MovingStart(probe);
    for (int c : method == Method::kPdLbfgs ? std::vector<int>{2, 5, 48} : std::vector<int>{3})
      CheckIdenticalGradients(scene, options, start, inputs, c,
                              std::string(ToString(method)) + ", " + std::to_string(c) + " checkpoints", 1e-9);
  }
}

// A small box dropped onto a frictional plane with a sideways velocity.
TEST(CheckpointedRolloutTest, FrictionalContactGradientsAreBitIdenticalToTheStoredRollout) {
  Scene scene;
  scene.mesh = MakeBoxHexMesh(Eigen::Vector3i(2, 2, 2), Vec3(0.04, 0.04, 0.04), Vec3(0, 0, 0.002));
  scene.material = MaterialParameters{1e5, 0.4, 1e3};
  scene.gravity = Vec3(0, 0, -9.81);
  FrictionalContact contact;
  contact.surface = ContactSurface::Plane(Vec3(0, 0, 1), 0.0);
  contact.nodes = BoundaryNodes(scene.mesh);
  scene.frictional_contacts = {contact};
  for (Method method : {Method::kPdLbfgs, Method::kNewtonCholesky}) {
    SolverOptions options = testing::TightOptions(method);
    options.time_step = 0.005;
    Simulator probe(scene, options);
    State start = probe.RestState();
    for (int i = 0; i < start.v.size() / 3; ++i) start.v.segment<3>(3 * i) = Vec3(0.3, 0.1, -0.5);
    const int steps = 17;
    const Rollout stored = probe.Simulate(start, std::vector<StepInput>(steps));
    int contact_steps = 0;
    for (const StepReport& r : stored.reports) contact_steps += !r.contact_nodes.empty();
    ASSERT_GE(contact_steps, 5) << ToString(method);
    CheckIdenticalGradients(scene, options, start, std::vector<StepInput>(steps), 2,
                            std::string(ToString(method)) + " on contact", 1e-9);
  }
}

TEST(CheckpointedRolloutTest, StreamedLossAndStepGradientsEqualTheStoredForm) {
  const Scene scene = testing::SmallBeamScene();
  Simulator sim(scene, testing::TightOptions(Method::kPdLbfgs));
  const int steps = 11;
  const State start = testing::MovingStart(sim);
  CheckpointOptions c;
  c.num_checkpoints = 2;
  const CheckpointedRollout r = sim.SimulateCheckpointed(start, std::vector<StepInput>(steps), c);
  const LossGradient loss = SomeLoss(sim.num_dofs(), steps, 3);
  const RolloutGradient expected = sim.Backward(r, loss);
  std::vector<int> asked;
  std::vector<VectorXd> forces(steps);
  StateLossGradient streamed;
  streamed.state_gradient = [&](int k, const State&, VectorXd* dx, VectorXd* dv) {
    asked.push_back(k);
    *dx = loss.dx[k];
    *dv = loss.dv[k];
  };
  streamed.step_gradient = [&](int k, const VectorXd& f, const VectorXd& a) {
    forces[k] = f;
    EXPECT_EQ(a.size(), 0);
  };
  const RolloutGradient g = sim.Backward(r, streamed);
  ASSERT_EQ(static_cast<int>(asked.size()), steps + 1);
  for (int k = 0; k <= steps; ++k) EXPECT_EQ(asked[k], steps - k);
  EXPECT_TRUE(g.external_force.empty());
  for (int k = 0; k < steps; ++k) EXPECT_EQ(forces[k], expected.external_force[k]) << "step " << k;
  EXPECT_EQ(g.x0, expected.x0);
  EXPECT_EQ(g.youngs_modulus, expected.youngs_modulus);
}

TEST(CheckpointedRolloutTest, BadCheckpointsAndLossesAreRejectedWithTheirMessages) {
  const Scene scene = testing::SmallBeamScene();
  Simulator sim(scene, testing::TightOptions(Method::kPd));
  CheckpointOptions none;
  none.num_checkpoints = 0;
  ASSERT_THROW_MESSAGE(sim.SimulateCheckpointed(sim.RestState(), std::vector<StepInput>(3), none), InvalidInputError,
                       "checkpoint options: num_checkpoints = 0 is invalid: must be >= 1");
  CheckpointOptions two;
  two.num_checkpoints = 2;
  const CheckpointedRollout r = sim.SimulateCheckpointed(sim.RestState(), std::vector<StepInput>(9), two);
  CheckpointedRollout moved = r;
  moved.checkpoint_steps.back() += 1;
  ASSERT_THROW_MESSAGE(sim.Backward(moved, LossGradient(9)), InvalidInputError,
                       "Backward: the checkpointed rollout's checkpoints are not those SimulateCheckpointed keeps "
                       "for its number of steps and checkpoint options");
  CheckpointedRollout short_state = r;
  short_state.checkpoints[0].v.resize(5);
  ASSERT_THROW_MESSAGE(sim.Backward(short_state, LossGradient(9)), InvalidInputError,
                       "Backward: the checkpointed rollout's checkpoint 0 has v with 5 entries, expected " +
                           std::to_string(sim.num_dofs()) + " finite ones (3 x number of nodes)");
  ASSERT_THROW_MESSAGE(sim.Backward(r, LossGradient(8)), InvalidInputError,
                       "Backward: the loss gradient must have 10 entries in dx and dv (got 9 and 9)");
  StateLossGradient bad;
  bad.state_gradient = [](int k, const State&, VectorXd* dx, VectorXd*) {
    if (k == 3) *dx = VectorXd::Ones(5);
  };
  ASSERT_THROW_MESSAGE(sim.Backward(r, bad), InvalidInputError,
                       "Backward: the loss's dL/dx_3 has 5 entries, expected 0 or " + std::to_string(sim.num_dofs()) +
                           " finite ones (3 x number of nodes)");
  CheckpointedRollout warm = r;
  warm.options.svd_warm_start = true;
  ASSERT_THROW_MESSAGE(sim.Backward(warm, LossGradient(9)), InvalidInputError,
                       "Backward: the checkpointed rollout's options have svd_warm_start = true; its steps cannot be "
                       "recomputed bit for bit (SimulateCheckpointed sets it false)");
  ASSERT_THROW_MESSAGE(sim.Tangents(warm, {InputDirection::YoungsModulus()}), InvalidInputError,
                       "Tangents: the checkpointed rollout's options have svd_warm_start = true; its steps cannot be "
                       "recomputed bit for bit (SimulateCheckpointed sets it false)");
  LossGradient nan_loss(9);
  nan_loss.dv[3] = VectorXd::Constant(sim.num_dofs(), std::nan(""));
  ASSERT_THROW_MESSAGE(sim.Backward(r, nan_loss), InvalidInputError, "loss.dv has a non-finite entry");
  SolverOptions other = sim.options();
  other.time_step = 0.02;
  sim.SetOptions(other);
  ASSERT_THROW_MESSAGE(sim.Backward(r, LossGradient(9)), InvalidInputError,
                       "Backward: the rollout was made with another time step (0.01 s) than the simulator's current "
                       "one (0.02 s)");
}

}  // namespace
}  // namespace diffpd
