// Rollout::Truncated (rollout.h): what the truncated rollout holds, that the
// adjoint of a loss on the first k states is the same on the rollout
// truncated after step k as on the whole rollout, and the range check.
#include <gtest/gtest.h>

#include "diffpd/error.h"
#include "test_scenes.h"

namespace diffpd {
namespace {

// The small beam under a tip force that varies per step, 6 steps.
struct ForcedBeam {
  Simulator sim{testing::SmallBeamScene(), testing::TightOptions(Method::kNewtonCholesky)};
  Rollout rollout;
  ForcedBeam() {
    std::vector<StepInput> inputs(6);
    for (int k = 0; k < 6; ++k) {
      inputs[k].external_force = VectorXd::Zero(sim.num_dofs());
      inputs[k].external_force(sim.num_dofs() - 1) = 0.05 * (k + 1);
    }
    rollout = sim.Simulate(sim.RestState(), inputs);
  }
};

TEST(RolloutTest, TruncatedKeepsTheFirstStepsAndTheSettings) {
  ForcedBeam beam;
  const Rollout head = beam.rollout.Truncated(4);
  EXPECT_EQ(head.num_steps(), 4);
  ASSERT_EQ(head.states.size(), 5u);
  ASSERT_EQ(head.reports.size(), 4u);
  for (int k = 0; k <= 4; ++k) {
    EXPECT_EQ(head.states[k].x, beam.rollout.states[k].x);
    EXPECT_EQ(head.states[k].v, beam.rollout.states[k].v);
  }
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(head.inputs[k].external_force, beam.rollout.inputs[k].external_force);
    EXPECT_EQ(head.reports[k].iterations, beam.rollout.reports[k].iterations);
  }
  EXPECT_EQ(head.material.youngs_modulus, beam.rollout.material.youngs_modulus);
  EXPECT_EQ(head.options.time_step, beam.rollout.options.time_step);
  EXPECT_EQ(head.options.method, beam.rollout.options.method);
  EXPECT_EQ(beam.rollout.Truncated(0).states.size(), 1u);
  EXPECT_EQ(beam.rollout.Truncated(6).num_steps(), 6);
}

TEST(RolloutTest, AdjointOfAnEarlyLossIsTheSameOnTheTruncatedRollout) {
  ForcedBeam beam;
  const int k = 3, n = beam.sim.num_dofs();
  // L = c . x_k + d . v_k with fixed pseudo-random c, d.
  const VectorXd c = VectorXd::LinSpaced(n, -1.0, 2.0), d = VectorXd::LinSpaced(n, 0.5, -0.5);
  LossGradient full_loss(6), head_loss(k);
  full_loss.dx[k] = head_loss.dx[k] = c;
  full_loss.dv[k] = head_loss.dv[k] = d;
  const RolloutGradient full = beam.sim.Backward(beam.rollout, full_loss);
  const RolloutGradient head = beam.sim.Backward(beam.rollout.Truncated(k), head_loss);
  const double scale = full.x0.cwiseAbs().maxCoeff();
  ASSERT_GT(scale, 0);
  EXPECT_LE((full.x0 - head.x0).cwiseAbs().maxCoeff(), 1e-12 * scale);
  EXPECT_LE((full.v0 - head.v0).cwiseAbs().maxCoeff(), 1e-12 * full.v0.cwiseAbs().maxCoeff());
  EXPECT_NEAR(full.youngs_modulus, head.youngs_modulus, 1e-12 * std::abs(full.youngs_modulus));
  EXPECT_NEAR(full.density, head.density, 1e-12 * std::abs(full.density));
  ASSERT_EQ(head.external_force.size(), size_t(k));
  for (int i = 0; i < k; ++i)
    EXPECT_LE((full.external_force[i] - head.external_force[i]).cwiseAbs().maxCoeff(),
              1e-12 * full.external_force[i].cwiseAbs().maxCoeff())
        << "step " << i;
  for (int i = k; i < 6; ++i) EXPECT_EQ(full.external_force[i].cwiseAbs().maxCoeff(), 0.0) << "step " << i;
}

TEST(RolloutTest, TruncatedRefusesAStepCountOutOfRange) {
  ForcedBeam beam;
  for (int bad : {-1, 7}) {
    try {
      beam.rollout.Truncated(bad);
      ADD_FAILURE() << "no throw for " << bad;
    } catch (const InvalidInputError& e) {
      EXPECT_EQ(std::string(e.what()), "Truncated: num_steps = " + std::to_string(bad) + " is out of range [0, 6]");
    }
  }
}

}  // namespace
}  // namespace diffpd
