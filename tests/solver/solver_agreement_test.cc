// All implicit methods converge to the same step (Newton-Cholesky, Newton-PCG,
// PD, PD-LBFGS), for every material each supports; PD backward agrees with
// the Newton backward.
#include <gtest/gtest.h>

#include "diffpd/error.h"
#include "diffpd/simulator.h"
#include "test_scenes.h"
#include "util/expect_message.h"

namespace diffpd {
namespace {

SolverOptions Tight(Method m) {
  SolverOptions o;
  o.method = m;
  o.rel_tolerance = 1e-12;
  o.abs_tolerance = 1e-12;
  o.max_iterations = 50000;
  o.num_threads = 1;
  return o;
}

State Deformed(const Simulator& sim) {
  State s = sim.RestState();
  for (int i = 0; i < s.x.size() / 3; ++i) s.x(3 * i + 2) += 0.3 * s.x(3 * i) * s.x(3 * i);
  return s;
}

TEST(SolverAgreementTest, AllImplicitMethodsReachTheSameStateAndGradient) {
  const Scene scene = testing::SmallBeamScene();
  Simulator ref(scene, Tight(Method::kNewtonCholesky));
  const State s0 = Deformed(ref);
  const Rollout r_ref = ref.Simulate(s0, std::vector<StepInput>(3));
  LossGradient dl(3);
  dl.dx[3] = VectorXd::LinSpaced(ref.num_dofs(), -1, 1);
  const RolloutGradient g_ref = ref.Backward(r_ref, dl);
  for (const Method m : {Method::kNewtonPcg, Method::kPd, Method::kPdLbfgs}) {
    Simulator sim(scene, Tight(m));
    const Rollout r = sim.Simulate(s0, std::vector<StepInput>(3));
    const double state_err = (r.states.back().x - r_ref.states.back().x).norm() / r_ref.states.back().x.norm();
    EXPECT_LT(state_err, 1e-10) << ToString(m);
    const RolloutGradient g = sim.Backward(r, dl);
    EXPECT_LT((g.x0 - g_ref.x0).norm() / g_ref.x0.norm(), 1e-8) << ToString(m);
    EXPECT_NEAR(g.youngs_modulus, g_ref.youngs_modulus, 1e-8 * std::abs(g_ref.youngs_modulus)) << ToString(m);
  }
}

TEST(SolverAgreementTest, PaperStyleNewtonLdltAgreesWithNewtonCholeskyForwardAndBackward) {
  const Scene scene = testing::SmallBeamScene();
  Simulator cholesky(scene, Tight(Method::kNewtonCholesky));
  Simulator ldlt(scene, Tight(Method::kNewtonLdlt));
  const State s0 = Deformed(cholesky);
  const Rollout rc = cholesky.Simulate(s0, std::vector<StepInput>(3));
  const Rollout rl = ldlt.Simulate(s0, std::vector<StepInput>(3));
  for (int k = 1; k <= 3; ++k) {
    EXPECT_LT((rl.states[k].x - rc.states[k].x).norm(), 1e-10 * rc.states[k].x.norm()) << k;
    EXPECT_EQ(rl.reports[k - 1].iterations, rc.reports[k - 1].iterations) << k;
  }
  LossGradient dl(3);
  dl.dx[3] = VectorXd::LinSpaced(cholesky.num_dofs(), -1, 1);
  dl.dv[3] = VectorXd::LinSpaced(cholesky.num_dofs(), 2, -1);
  const RolloutGradient gc = cholesky.Backward(rc, dl), gl = ldlt.Backward(rl, dl);
  EXPECT_LT((gl.x0 - gc.x0).norm() / gc.x0.norm(), 1e-8);
  EXPECT_LT((gl.v0 - gc.v0).norm() / gc.v0.norm(), 1e-8);
  EXPECT_NEAR(gl.youngs_modulus, gc.youngs_modulus, 1e-8 * std::abs(gc.youngs_modulus));
  EXPECT_EQ(gl.report.direct_steps, 3);
}

TEST(SolverAgreementTest, PdLbfgsPreconditionerScaleChangesNeitherTheStateNorTheGradient) {
  // lbfgs_weight_scale only changes the initial Hessian A of PD-LBFGS (and
  // its backward): every scale must converge to the same step and adjoint.
  const Scene scene = testing::SmallBeamScene();
  LossGradient dl(3);
  Rollout r_ref;
  RolloutGradient g_ref;
  for (const double scale : {1.0, 0.6, 0.3}) {
    SolverOptions o = Tight(Method::kPdLbfgs);
    o.lbfgs_weight_scale = scale;
    Simulator sim(scene, o);
    const State s0 = Deformed(sim);
    dl.dx[3] = VectorXd::LinSpaced(sim.num_dofs(), -1, 1);
    const Rollout r = sim.Simulate(s0, std::vector<StepInput>(3));
    const RolloutGradient g = sim.Backward(r, dl);
    EXPECT_EQ(sim.num_pd_factorizations(), 1) << scale;
    if (scale == 1.0) {
      r_ref = r;
      g_ref = g;
      continue;
    }
    EXPECT_LT((r.states.back().x - r_ref.states.back().x).norm() / r_ref.states.back().x.norm(), 1e-10) << scale;
    EXPECT_LT((g.x0 - g_ref.x0).norm() / g_ref.x0.norm(), 1e-8) << scale;
    EXPECT_NEAR(g.youngs_modulus, g_ref.youngs_modulus, 1e-8 * std::abs(g_ref.youngs_modulus)) << scale;
  }
}

TEST(SolverAgreementTest, NonProjectiveMaterialsAgreeBetweenNewtonAndPdLbfgs) {
  for (const ElasticEnergy e : {ElasticEnergy::kNeoHookean, ElasticEnergy::kCorotated, ElasticEnergy::kLinear}) {
    const Scene scene = testing::SmallBeamScene(false, {e});
    Simulator newton(scene, Tight(Method::kNewtonCholesky));
    Simulator lbfgs(scene, Tight(Method::kPdLbfgs));
    const State s0 = Deformed(newton);
    const State a = newton.Step(s0, StepInput());
    const State b = lbfgs.Step(s0, StepInput());
    EXPECT_LT((a.x - b.x).norm() / a.x.norm(), 1e-10) << ToString(e);
  }
}

TEST(SolverAgreementTest, PdRejectsNonProjectiveEnergiesWithAClearMessage) {
  const Scene scene = testing::SmallBeamScene(false, {ElasticEnergy::kNeoHookean});
  Simulator sim(scene, Tight(Method::kPd));
  ASSERT_THROW_MESSAGE(sim.Step(sim.RestState(), StepInput()), InvalidInputError,
                       "method pd needs projective energies only (pd-corotated, pd-volume); use pd-lbfgs or newton");
}

TEST(SolverAgreementTest, NonConvergenceIsReportedNotReturned) {
  const Scene scene = testing::SmallBeamScene();
  SolverOptions o = Tight(Method::kPd);
  o.max_iterations = 2;
  Simulator sim(scene, o);
  try {
    sim.Step(Deformed(sim), StepInput());
    FAIL() << "expected SolverError";
  } catch (const SolverError& e) {
    EXPECT_EQ(e.status(), SolverStatus::kMaxIterations);
    EXPECT_NE(std::string(e.what()).find("pd: the step did not converge in 2 iterations"), std::string::npos)
        << e.what();
  }
}

TEST(SolverAgreementTest, PdBackwardFallsBackToADirectSolveWhenTheIterationFails) {
  const Scene scene = testing::SmallBeamScene();
  SolverOptions o = Tight(Method::kPd);
  o.pd_backward = PdBackwardMethod::kFixedPoint;
  o.adjoint_solver = AdjointSolver::kIterative;
  o.backward_max_iterations = 1;  // forces the fallback
  Simulator sim(scene, o);
  const Rollout r = sim.Simulate(Deformed(sim), std::vector<StepInput>(2));
  LossGradient dl(2);
  dl.dx[2] = VectorXd::Ones(sim.num_dofs());
  const RolloutGradient g = sim.Backward(r, dl);
  EXPECT_EQ(g.report.fallbacks, 2);
  Simulator ref(scene, Tight(Method::kNewtonCholesky));
  const RolloutGradient g_ref = ref.Backward(ref.Simulate(Deformed(sim), std::vector<StepInput>(2)), dl);
  EXPECT_LT((g.x0 - g_ref.x0).norm() / g_ref.x0.norm(), 1e-8);
}

}  // namespace
}  // namespace diffpd
