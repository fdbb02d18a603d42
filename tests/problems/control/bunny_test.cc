// The bunny problem (problems/control/bunny.h) on its small instance: Ipopt's
// derivative checker, a solve that lands the bunny on target after clearing
// the wall, and an unreachable wall reported as infeasible by the program.
#include "control/bunny.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "diffpd/simulator.h"
#include "util/temporary_directory.h"

namespace diffpd::problems {
namespace {

using solvers::IpoptOptions;
using solvers::IpoptSummary;

SolverOptions Options(const Bunny& bunny, Method method, double rel_tolerance) {
  SolverOptions o = bunny.BaseOptions(InstanceSize::kSmall);
  o.method = method;
  o.time_step = bunny.time_step(InstanceSize::kSmall);
  o.num_threads = 1;
  o.rel_tolerance = rel_tolerance;
  return o;
}

TEST(IpoptBunnyTest, DerivativeCheckerReportsNoError) {
  const Bunny bunny;
  auto nlp = bunny.MakeNlp(Options(bunny, Method::kNewtonCholesky, 1e-11), InstanceSize::kSmall);
  IpoptOptions o;
  o.string_options = {{"derivative_test", "first-order"}};
  o.int_options = {{"max_iter", 0}};
  o.num_options = {{"derivative_test_perturbation", 1e-7}, {"point_perturbation_radius", 0.0}};
  const IpoptSummary s = SolveWithIpopt(nlp, o);
  EXPECT_EQ(s.derivative_checker_errors, 0) << s.log;
}

TEST(IpoptBunnyTest, SmallInstanceLandsOnTargetAfterClearingTheWall) {
  const Bunny bunny;
  auto nlp = bunny.MakeNlp(Options(bunny, Method::kNewtonCholesky, 1e-6), InstanceSize::kSmall);
  const IpoptSummary s = SolveWithIpopt(nlp, bunny.DefaultIpoptOptions(InstanceSize::kSmall));
  ASSERT_TRUE(s.succeeded()) << s.BriefReport() << "\n" << s.log;
  EXPECT_LE(s.constraint_violation, 1e-6);
  // The stated margin: the landing error drops by 90 % (here by far more).
  EXPECT_LE(s.objective, (1 - bunny.improvement_margin()) * s.initial_objective) << s.BriefReport();
  EXPECT_LE(std::sqrt(s.objective), 1e-3);  // within 1 mm of the target
  // It really lands: the ground holds nodes at the last step, and the start
  // guess did not clear the wall.
  const Rollout* r = nlp->RolloutAt(s.x);
  ASSERT_NE(r, nullptr);
  EXPECT_GT(r->reports.back().contact_nodes.size(), 3u);
  VectorXd g;
  ASSERT_TRUE(nlp->Constraints(nlp->starting_point(), &g));
  EXPECT_LT(g(0), 0.10);
}

TEST(IpoptBunnyTest, UnreachableWallIsReportedInfeasibleByTheProgram) {
  BunnyOptions options;
  options.wall_height = 1.0;  // a 3 m/s throw rises 0.46 m at most
  const Bunny bunny(options);
  CommandArgs args;
  args.problem = "bunny";
  args.small = true;
  args.method = Method::kNewtonCholesky;
  args.compare_newton = false;
  args.threads = 1;
  args.json = true;
  const testing::TemporaryDirectory dir("diffpd-ipopt-bunny-infeasible");
  args.out_dir = dir.path().string();
  ::testing::internal::CaptureStdout();
  ::testing::internal::CaptureStderr();
  const int code = bunny.Run(args);
  const std::string out = ::testing::internal::GetCapturedStdout();
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(code, 4) << err;
  const nlohmann::json j = nlohmann::json::parse(out);
  EXPECT_EQ(j["status"], "Infeasible_Problem_Detected") << out;
  EXPECT_GT(j["constraint_violation"].get<double>(), 0.4);
  for (const char* key : {"objective", "initial_objective", "evaluations", "forward_s", "backward_s"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_NE(err.find("diffpd: bunny: Ipopt reports the problem infeasible: the constraints cannot be met "
                     "(Infeasible_Problem_Detected)"),
            std::string::npos)
      << err;
}

}  // namespace
}  // namespace diffpd::problems
