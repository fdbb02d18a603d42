// PD-LBFGS hands a step whose line search stalls above the rounding floor,
// or that reaches max_iterations, to Newton from where it stopped
// (SolverOptions::pd_lbfgs_newton_fallback), which meets the same
// convergence test; without the fallback the stall or the limit is an error.
#include <gtest/gtest.h>

#include <string>

#include "diffpd/error.h"
#include "diffpd/simulator.h"
#include "test_scenes.h"

namespace diffpd {
namespace {

// PD-LBFGS to rtol 1e-10 on one thread, with or without the fallback.
SolverOptions TightPdLbfgs(bool fallback) {
  SolverOptions o;
  o.method = Method::kPdLbfgs;
  o.time_step = 0.01;
  o.rel_tolerance = 1e-10;
  o.abs_tolerance = 1e-12;
  o.num_threads = 1;
  o.pd_lbfgs_newton_fallback = fallback;
  return o;
}

// A preconditioner with almost no elastic stiffness (A ~ M / h^2) makes the
// first PD-LBFGS directions far too long in the stiff modes; with two
// halvings allowed the line search stalls on the first iteration, far above
// g's rounding floor. A stand-in for the stalls of stiff, nearly
// incompressible material at large h (`diffpd stress`), which depend
// on rounding paths.
SolverOptions StallingOptions(bool fallback) {
  SolverOptions o = TightPdLbfgs(fallback);
  o.lbfgs_weight_scale = 1e-6;
  o.max_line_search_steps = 2;
  return o;
}

// Five PD-LBFGS iterations cannot reach rtol 1e-10 on the moving beam;
// five Newton iterations can.
SolverOptions IterationLimitedOptions(bool fallback) {
  SolverOptions o = TightPdLbfgs(fallback);
  o.max_iterations = 5;
  return o;
}

// The error of one step of the moving beam (a failure if it succeeds).
SolverError StepError(const SolverOptions& options) {
  Simulator sim(testing::SmallBeamScene(), options);
  try {
    sim.Step(testing::MovingStart(sim), StepInput());
  } catch (const SolverError& e) {
    return e;
  }
  ADD_FAILURE() << "expected the step to fail";
  return SolverError(SolverStatus::kConverged, "");
}

// One step of the moving beam with the fallback: Newton finished it, to the
// PD-LBFGS test, at the state a tight Newton-Cholesky step reaches.
StepReport ExpectNewtonFinishesTheStep(const SolverOptions& options) {
  Simulator sim(testing::SmallBeamScene(), options);
  const State start = testing::MovingStart(sim);
  StepReport report;
  const State next = sim.Step(start, StepInput(), &report);
  EXPECT_TRUE(report.newton_fallback);
  EXPECT_LE(report.final_residual, 1e-12 + 1e-10 * report.initial_residual);

  SolverOptions newton = testing::TightOptions(Method::kNewtonCholesky);
  newton.time_step = 0.01;
  Simulator reference(testing::SmallBeamScene(), newton);
  const State expected = reference.Step(start, StepInput());
  EXPECT_LT((next.x - expected.x).norm(), 1e-9 * expected.x.norm());
  return report;
}

TEST(NewtonFallbackTest, WithoutTheFallbackTheStallIsALineSearchError) {
  const SolverError e = StepError(StallingOptions(false));
  EXPECT_EQ(e.status(), SolverStatus::kLineSearchFailed) << e.what();
}

TEST(NewtonFallbackTest, NewtonFinishesTheStalledStepAtTheSameTest) {
  const StepReport report = ExpectNewtonFinishesTheStep(StallingOptions(true));
  EXPECT_FALSE(report.rounding_floor_stop);
}

TEST(NewtonFallbackTest, OrdinaryStepsNeverFallBack) {
  SolverOptions o;
  o.method = Method::kPdLbfgs;
  o.time_step = 0.01;
  o.num_threads = 1;
  Simulator sim(testing::SmallBeamScene(), o);
  const Rollout r = sim.Simulate(testing::MovingStart(sim), std::vector<StepInput>(20));
  for (const StepReport& report : r.reports) EXPECT_FALSE(report.newton_fallback);
}

TEST(NewtonFallbackTest, WithoutTheFallbackTheIterationLimitIsAnError) {
  const SolverError e = StepError(IterationLimitedOptions(false));
  EXPECT_EQ(e.status(), SolverStatus::kMaxIterations) << e.what();
  EXPECT_NE(std::string(e.what()).find("pd-lbfgs: the step did not converge in 5 iterations"), std::string::npos)
      << e.what();
}

TEST(NewtonFallbackTest, NewtonFinishesAStepThatReachedTheIterationLimit) {
  const StepReport report = ExpectNewtonFinishesTheStep(IterationLimitedOptions(true));
  EXPECT_GT(report.iterations, 5);  // PD-LBFGS's 5 and Newton's
}

// When Newton cannot finish either, the error says so and what it took over from.
TEST(NewtonFallbackTest, AFallbackThatFailsNamesBothSolves) {
  SolverOptions o = IterationLimitedOptions(true);
  o.max_iterations = 1;
  const SolverError e = StepError(o);
  const std::string what = e.what();
  EXPECT_EQ(e.status(), SolverStatus::kMaxIterations) << what;
  EXPECT_NE(what.find("Newton fallback of pd-lbfgs: the step did not converge in 1 iterations"), std::string::npos)
      << what;
  EXPECT_NE(what.find("; Newton took over after: pd-lbfgs: the step did not converge in 1 iterations"),
            std::string::npos)
      << what;
}

}  // namespace
}  // namespace diffpd
