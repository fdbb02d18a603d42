// Checks shared by the locomotion tests (one executable per body keeps each
// under 20 s): Ipopt's derivative checker on a shortened small instance, and
// a few Ipopt iterations that must move the body forward without tipping.
#pragma once

#include <gtest/gtest.h>

#include "diffpd/simulator.h"
#include "control/locomotion.h"

namespace diffpd::problems::testing {

inline SolverOptions LocomotionOptions(const Locomotion& problem, double rel_tolerance, double abs_tolerance) {
  SolverOptions o = problem.BaseOptions(InstanceSize::kSmall);
  o.method = Method::kNewtonCholesky;
  o.time_step = problem.time_step(InstanceSize::kSmall);
  o.num_threads = 1;
  o.rel_tolerance = rel_tolerance;
  o.abs_tolerance = abs_tolerance;
  return o;
}

// Ipopt's first-order derivative checker at the starting point, over
// `steps` steps (contact starts at once: the body is released 1 mm above the ground).
inline void ExpectDerivativeCheckerPasses(Locomotion::Body body, int steps) {
  const Locomotion problem(body, steps);
  auto nlp = problem.MakeNlp(LocomotionOptions(problem, 1e-10, 1e-12), InstanceSize::kSmall);
  solvers::IpoptOptions o;
  o.string_options = {{"derivative_test", "first-order"}};
  o.int_options = {{"max_iter", 0}};
  o.num_options = {{"derivative_test_perturbation", 1e-7}, {"point_perturbation_radius", 0.0}};
  const solvers::IpoptSummary s = SolveWithIpopt(nlp, o);
  EXPECT_NE(s.log.find("Starting derivative checker for first derivatives."), std::string::npos);
  EXPECT_EQ(s.derivative_checker_errors, 0) << s.log;
  const Rollout* r = nlp->RolloutAt(nlp->starting_point());
  ASSERT_NE(r, nullptr);
  EXPECT_FALSE(r->reports.back().contact_nodes.empty());  // it stands on the ground
}

// `iterations` Ipopt iterations from the travelling-wave start: feasible
// (bounded activations, upright) and at least 0.2 cm more forward travel.
inline void ExpectForwardProgress(Locomotion::Body body, int steps, int iterations) {
  const Locomotion problem(body, steps);
  auto nlp = problem.MakeNlp(LocomotionOptions(problem, 1e-6, 1e-9), InstanceSize::kSmall);
  solvers::IpoptOptions o = problem.DefaultIpoptOptions(InstanceSize::kSmall);
  o.int_options.push_back({"max_iter", iterations});
  const solvers::IpoptSummary s = SolveWithIpopt(nlp, o);
  EXPECT_LE(s.constraint_violation, 1e-6) << s.BriefReport() << "\n" << s.log;
  EXPECT_LE(s.objective, problem.RequiredObjective(s.initial_objective)) << s.BriefReport() << "\n" << s.log;
}

}  // namespace diffpd::problems::testing
