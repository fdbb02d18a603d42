// The routing-tendon optimisation (problems/control/routing_tendon_opt.h), small
// instance: Ipopt's derivative checker, and a solve that brings the tip to
// its target with activations within their bounds.
#include "control/routing_tendon_opt.h"

#include <gtest/gtest.h>

#include "diffpd/simulator.h"

namespace diffpd::problems {
namespace {

SolverOptions Options(const RoutingTendonOpt& p, double rel_tolerance, double abs_tolerance) {
  SolverOptions o = p.BaseOptions(InstanceSize::kSmall);
  o.method = Method::kNewtonCholesky;
  o.time_step = p.time_step(InstanceSize::kSmall);
  o.num_threads = 1;
  o.rel_tolerance = rel_tolerance;
  o.abs_tolerance = abs_tolerance;
  return o;
}

TEST(IpoptRoutingTendonTest, DerivativeCheckerReportsNoError) {
  const RoutingTendonOpt problem;
  // The objective is in mm^2: solve far below the checker's 1e-7 steps.
  auto nlp = problem.MakeNlp(Options(problem, 1e-12, 1e-12), InstanceSize::kSmall);
  solvers::IpoptOptions o;
  o.string_options = {{"derivative_test", "first-order"}};
  o.int_options = {{"max_iter", 0}};
  o.num_options = {{"derivative_test_perturbation", 1e-7}, {"point_perturbation_radius", 0.0}};
  const solvers::IpoptSummary s = SolveWithIpopt(nlp, o);
  EXPECT_EQ(s.derivative_checker_errors, 0) << s.log;
}

TEST(IpoptRoutingTendonTest, SmallInstanceBringsTheTipToItsTargetWithBoundedActivations) {
  const RoutingTendonOpt problem;
  auto nlp = problem.MakeNlp(Options(problem, 1e-6, 1e-9), InstanceSize::kSmall);
  const solvers::IpoptSummary s = SolveWithIpopt(nlp, problem.DefaultIpoptOptions(InstanceSize::kSmall));
  ASSERT_TRUE(s.succeeded()) << s.BriefReport() << "\n" << s.log;
  EXPECT_LE(s.constraint_violation, 1e-6);
  EXPECT_LE(s.objective, problem.RequiredObjective(s.initial_objective)) << s.BriefReport();
  EXPECT_LE(s.objective, 1e-2);  // the tip within 0.1 mm of the target (objective in mm^2)
  EXPECT_GE(s.x.minCoeff(), 0.6 - 1e-9);
  EXPECT_LE(s.x.maxCoeff(), 1.0 + 1e-9);
  EXPECT_LT(s.x.minCoeff(), 0.95);  // it had to contract some tendon
}

}  // namespace
}  // namespace diffpd::problems
